"""A plate that never fails."""

from __future__ import annotations

from typing import final

import attrs
import numpy as np

from plateimpact import BoundResistance, FailureModel, SceneBatch


@final
@attrs.frozen
class Intact(FailureModel):
    """The plate never fails, whatever P* says: the sphere ricochets or embeds.

    The report's force law has no back surface, so an intact plate behaves as a
    half-space; this is the report's "extremely large P*" limit.
    """

    name = "intact"

    def onset_penetration(self, batch: SceneBatch) -> np.ndarray:
        return np.full(batch.size, np.inf)

    def force_change(
        self,
        penetration: np.ndarray,
        obliquity: np.ndarray,
        speed: np.ndarray,
        state: np.ndarray,
        batch: SceneBatch,
        law: BoundResistance,
    ) -> tuple[np.ndarray, np.ndarray]:
        raise AssertionError("an intact plate has no failed scenes")  # onset is inf

    def perforation_margin(
        self, penetration: np.ndarray, obliquity: np.ndarray, batch: SceneBatch
    ) -> np.ndarray:
        return np.full(penetration.shape, -np.inf)
