"""Plugging failure (report eqs 8–15): material beyond a fixed plane stops resisting."""

from __future__ import annotations

from typing import final

import attrs
import numpy as np

from plateimpact import SceneBatch

from .report.constants import CRITICAL_PENETRATION, FAILURE_ANGLE
from .separation import PlaneSeparation


@final
@attrs.frozen
class Plugging(PlaneSeparation):
    """The report's plugging failure: separation at P = P* of the plate, along the plane
    of eq 8, relieving the material beyond it (see :class:`PlaneSeparation`)."""

    name = "plugging"
    plate_constants = (CRITICAL_PENETRATION, FAILURE_ANGLE)

    def onset_penetration(self, scenes: SceneBatch) -> np.ndarray:
        return scenes.critical_penetration
