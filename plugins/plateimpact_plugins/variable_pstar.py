"""Variable critical penetration for mild steel (report, Figures 38–44)."""

from __future__ import annotations

from typing import final

import attrs
import numpy as np

from plateimpact import SceneBatch

from .report.pstar_table import PSTAR_TABLE, SAE1010_TABLE, TABLE_COLUMNS, PstarTable
from .separation import PlaneSeparation

__all__ = ["SAE1010_TABLE", "TABLE_COLUMNS", "PstarTable", "VariablePstar"]


@final
@attrs.frozen
class VariablePstar(PlaneSeparation):
    """Plugging failure whose critical penetration depends on the impact conditions.

    The report finds that one P* does not fit mild steel: the ricochet data want a smaller
    P* than the perforation data, and both fall with obliquity. Here P* is set per scene,
    before integration, from the impact obliquity and impact speed through a
    :class:`PstarTable` (default: the report's SAE 1010 values). The plate's own P* is not
    used. Failure then proceeds as plugging, along the plane of eq 8 at that P*.

    Parameters
    ----------
    table : PstarTable, a sequence of rows, or a CSV path
    """

    name = "variable-pstar"

    table: PstarTable = PSTAR_TABLE.field()

    def onset_penetration(self, scenes: SceneBatch) -> np.ndarray:
        return self.table(scenes.impact_obliquity, scenes.impact_speed)
