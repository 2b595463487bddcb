"""Poncelet resistance with the report's obliquity factor (eq 1)."""

from __future__ import annotations

from typing import final

import attrs
import numpy as np

from plateimpact import ResistanceLaw, SceneBatch

from .plate_constants import DENSITY_B, STRENGTH_A


@final
@attrs.frozen
class Poncelet(ResistanceLaw):
    """σ = a + b V² cos² ψ [N/m²] (eq 1).

    a [N/m²] is the plate's quasi-static strength term, b [kg/m³] its inertial term;
    only the speed component along the force's line, V cos ψ, enters the inertial term.
    """

    name = "poncelet"
    plate_constants = (STRENGTH_A, DENSITY_B)

    def stress(self, speed: np.ndarray, incidence: np.ndarray, scenes: SceneBatch) -> np.ndarray:
        normal_speed = speed * np.cos(incidence)
        return scenes.a + scenes.b * normal_speed * normal_speed
