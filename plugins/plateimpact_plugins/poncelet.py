"""Poncelet resistance with the report's obliquity factor (eq 1)."""

from __future__ import annotations

from typing import Any, final

import attrs
import numpy as np

from plateimpact import ResistanceLaw, SceneBatch, elementary

from .report.constants import DENSITY_B, STRENGTH_A


def poncelet_stress(speed: Any, incidence: Any, a: Any, b: Any) -> Any:
    """σ = a + b (V cos ψ)² [N/m²] (eq 1) at speed V [m/s] and incidence ψ [rad], with a
    [N/m²] and b [kg/m³]: the formula once, on numbers or arrays alike (numpy arithmetic
    only, so that a compiled path can compile this very function; :func:`plateimpact.elementary.cos`
    rather than numpy's, so that lanes of scenes evaluate it in one SIMD pass)."""
    normal_speed = speed * elementary.cos(incidence)
    return a + b * normal_speed * normal_speed


def poncelet_stress_kernel(speed: float, incidence: float, constants: Any) -> float:
    """:func:`poncelet_stress` for the compiled path: ``constants`` is a scene's (a, b)."""
    return poncelet_stress(speed, incidence, constants[0], constants[1])


#: The functions of numbers a compiled path compiles (callees before callers).
KERNELS = (poncelet_stress, poncelet_stress_kernel)


@final
@attrs.frozen
class Poncelet(ResistanceLaw):
    """σ = a + b V² cos² ψ [N/m²] (eq 1).

    a [N/m²] is the plate's quasi-static strength term, b [kg/m³] its inertial term;
    only the speed component along the force's line, V cos ψ, enters the inertial term.
    """

    name = "poncelet"
    plate_constants = (STRENGTH_A, DENSITY_B)
    kernel_columns = ("a", "b")
    stress_kernel = poncelet_stress_kernel

    def stress(self, speed: np.ndarray, incidence: np.ndarray, scenes: SceneBatch) -> np.ndarray:
        return poncelet_stress(speed, incidence, scenes.a, scenes.b)
