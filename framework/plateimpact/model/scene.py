"""One impact: a sphere striking a plate at a speed and obliquity."""

from __future__ import annotations

import math

import attrs

from ..base.parameters import Parameter, Range, check_instance
from .bodies import Plate, Sphere

# From the speed of an indentation test (1 mm/s: the strength term a alone) to 10 km/s,
# past which a sphere melts or vaporises on impact and no rigid-sphere Poncelet law holds
# (docs/robustness.md, "the input domain").
IMPACT_SPEED = Parameter("impact_speed", "impact speed Vs", "m/s", Range(1e-3, 1e4), flag="--speed")
IMPACT_OBLIQUITY = Parameter(
    "impact_obliquity",
    "impact obliquity theta_s, the velocity's angle from the plate's inward normal",
    "rad",
    Range(0.0, math.pi / 2, high_open=True),
    "deg",
    math.pi / 180,
    flag="--obliquity",
)


@attrs.frozen
class Scene:
    """The initial conditions of one impact.

    Parameters
    ----------
    sphere : Sphere
    plate : Plate
    impact_speed : float
        Vs [m/s], in [1e-3, 1e4].
    impact_obliquity : float
        θs, angle of the velocity from the plate's inward normal [rad], in [0, π/2).
    """

    sphere: Sphere = attrs.field(validator=lambda _, a, v: check_instance(a.name, v, Sphere))
    plate: Plate = attrs.field(validator=lambda _, a, v: check_instance(a.name, v, Plate))
    impact_speed: float = IMPACT_SPEED.field()
    impact_obliquity: float = IMPACT_OBLIQUITY.field()
