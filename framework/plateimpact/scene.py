"""One impact: a sphere striking a plate at a speed and obliquity."""

from __future__ import annotations

import attrs

from . import validation as v
from .bodies import Plate, Sphere


@attrs.frozen
class Scene:
    """The initial conditions of one impact.

    Parameters
    ----------
    sphere : Sphere
    plate : Plate
    impact_speed : float
        Vs [m/s], > 0.
    impact_obliquity : float
        θs, angle of the velocity from the plate's inward normal [rad], in [0, π/2).
    """

    sphere: Sphere = attrs.field(validator=attrs.validators.instance_of(Sphere))
    plate: Plate = attrs.field(validator=attrs.validators.instance_of(Plate))
    impact_speed: float = v.IMPACT_SPEED.field()
    impact_obliquity: float = v.IMPACT_OBLIQUITY.field()
