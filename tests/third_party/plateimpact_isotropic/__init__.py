"""A third-party plug-in package: two resistance laws that are not the report's.

* ``isotropic-poncelet``: σ = a + b V² [N/m²], the classical form the report starts
  from ("F = A(a + bV²)"), whatever the angle between the path and the force. It equals
  eq 1 at normal incidence.
* ``rate-poncelet``: eq 1 with a strength term that rises with the speed into the plate,
  σ = a (1 + c ln(1 + V cos ψ / V_ref)) + b V² cos² ψ. It brings its own plate constant,
  the rate sensitivity ``c`` [1], and a setting, the reference speed ``V_ref`` [m/s]; with
  c = 0 it is eq 1 exactly.

Nothing in plateimpact's core knows either: they are declared here and registered
through the ``plateimpact`` entry-point group.
"""

from __future__ import annotations

from typing import final

import attrs
import numpy as np

from plateimpact import Parameter, PluginRegistry, Range, ResistanceLaw, SceneBatch, hookimpl
from plateimpact_plugins.report import DENSITY_B, STRENGTH_A

RATE_SENSITIVITY = Parameter(
    "rate_sensitivity",
    "rate sensitivity c of the strength term: a (1 + c ln(1 + V cos psi / V_ref))",
    range=Range(0.0),
    default=0.0,
    flag="--c",
    short="c",
)
REFERENCE_SPEED = Parameter(
    "reference_speed",
    "reference speed V_ref of the rate term",
    "m/s",
    Range(0.0, low_open=True),
    default=100.0,
)


@final
@attrs.frozen
class RatePoncelet(ResistanceLaw):
    """σ = a (1 + c ln(1 + V cos ψ / V_ref)) + b V² cos² ψ [N/m²]."""

    name = "rate-poncelet"
    plate_constants = (STRENGTH_A, DENSITY_B, RATE_SENSITIVITY)

    reference_speed: float = REFERENCE_SPEED.field()

    def stress(self, speed: np.ndarray, incidence: np.ndarray, batch: SceneBatch) -> np.ndarray:
        normal_speed = speed * np.cos(incidence)
        rate = np.log1p(np.maximum(normal_speed, 0.0) / self.reference_speed)
        strength = batch.a * (1.0 + batch.rate_sensitivity * rate)
        return strength + batch.b * normal_speed * normal_speed


@final
@attrs.frozen
class IsotropicPoncelet(ResistanceLaw):
    """σ = a + b V² [N/m²]."""

    name = "isotropic-poncelet"
    plate_constants = (STRENGTH_A, DENSITY_B)

    def stress(self, speed: np.ndarray, incidence: np.ndarray, batch: SceneBatch) -> np.ndarray:
        return batch.a + batch.b * speed * speed


@hookimpl
def plateimpact_register(registry: PluginRegistry) -> None:
    registry.add(IsotropicPoncelet)
    registry.add(RatePoncelet)
