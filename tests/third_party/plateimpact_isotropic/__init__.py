"""A third-party plug-in package: two resistance laws that are not the report's, a
failure model and an integrator.

* ``isotropic-poncelet``: σ = a + b V² [N/m²], the classical form the report starts
  from ("F = A(a + bV²)"), whatever the angle between the path and the force. It equals
  eq 1 at normal incidence.
* ``rate-poncelet``: eq 1 with a strength term that rises with the speed into the plate,
  σ = a (1 + c ln(1 + V cos ψ / V_ref)) + b V² cos² ψ. It brings its own plate constant,
  the rate sensitivity ``c`` [1], and a setting, the reference speed ``V_ref`` [m/s]; with
  c = 0 it is eq 1 exactly.
* ``brittle`` (:mod:`.brittle`): a brittle plate that breaks up at P* and keeps a
  fraction of its resistance until the sphere has passed its back face.
* ``rk4`` (:mod:`.rk4`): classical fourth-order Runge–Kutta at a fixed step.

Nothing in plateimpact's core knows any of them: they are written against the public
contract (docs/plugins.md, where each is shown), declared here and registered through the
``plateimpact`` entry-point group.
"""

from __future__ import annotations

from typing import Any, final

import attrs
import numpy as np

from plateimpact import Parameter, PluginRegistry, Range, ResistanceLaw, SceneBatch, hookimpl
from plateimpact_plugins.report import DENSITY_B, STRENGTH_A

from .brittle import Brittle
from .rk4 import ClassicalRungeKutta

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

    def stress(self, speed: np.ndarray, incidence: np.ndarray, scenes: SceneBatch) -> np.ndarray:
        normal_speed = speed * np.cos(incidence)
        rate = np.log1p(np.maximum(normal_speed, 0.0) / self.reference_speed)
        strength = scenes.a * (1.0 + scenes.rate_sensitivity * rate)
        return strength + scenes.b * normal_speed * normal_speed


def isotropic_stress(speed: Any, incidence: Any, constants: Any) -> Any:
    """σ = a + b V² [N/m²] at speed V [m/s], whatever the incidence ψ [rad]; constants
    (a [N/m²], b [kg/m³]): the formula once, for arrays and for numbers."""
    return constants[0] + constants[1] * speed * speed


#: The functions of numbers the compiled path compiles.
KERNELS = (isotropic_stress,)


@final
@attrs.frozen
class IsotropicPoncelet(ResistanceLaw):
    """σ = a + b V² [N/m²], on the compiled path too."""

    name = "isotropic-poncelet"
    plate_constants = (STRENGTH_A, DENSITY_B)
    kernel_columns = ("a", "b")  # a scene's constants, in this order
    stress_kernel = isotropic_stress

    def stress(self, speed: np.ndarray, incidence: np.ndarray, scenes: SceneBatch) -> np.ndarray:
        return isotropic_stress(speed, incidence, (scenes.a, scenes.b))


# The package's one hook registers its plug-ins: this law and those further down.
@hookimpl
def plateimpact_register(registry: PluginRegistry) -> None:
    for cls in (IsotropicPoncelet, RatePoncelet, Brittle, ClassicalRungeKutta):
        registry.add(cls)
