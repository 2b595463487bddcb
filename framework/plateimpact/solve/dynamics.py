"""The active scenes as an ODE dy/dt = f(y): what a stepper may evaluate."""

from __future__ import annotations

from typing import Any

import numpy as np

from ..model.binding import BoundBatch
from ..model.impact import LATERAL, PENETRATION, SPEED, ImpactModel


class Dynamics:
    """The right-hand side, event and branch margins of the scenes still running, with
    their failure and hold flags fixed for the current step.

    Every evaluation of the right-hand side is counted (``stats["force_evaluations"]``).
    """

    __slots__ = ("batch", "failed", "held", "model", "stats")

    def __init__(
        self,
        model: ImpactModel,
        batch: BoundBatch,
        failed: np.ndarray,
        held: np.ndarray,
        stats: dict[str, Any],
    ) -> None:
        self.model = model
        self.batch = batch
        self.failed = failed
        self.held = held
        self.stats = stats

    @property
    def size(self) -> int:
        return self.batch.size

    @property
    def time_scale(self) -> np.ndarray:
        """Rs/Vs per scene [s]: the time to travel one radius at impact speed."""
        core = self.batch.core
        return core.radius / core.impact_speed

    def component_scale(self, width: int) -> np.ndarray:
        """Each state component's natural size, shape (width, n): Rs for P and Y [m],
        1 rad for θ and the failure state, Vs for V [m/s]."""
        core = self.batch.core
        scale = np.ones((width, self.size))
        scale[PENETRATION] = scale[LATERAL] = core.radius
        scale[SPEED] = core.impact_speed
        return scale

    def take(self, index: np.ndarray) -> Dynamics:
        """The dynamics of the scenes at ``index``."""
        return Dynamics(
            self.model, self.batch.take(index), self.failed[index], self.held[index], self.stats
        )

    def rates(self, y: np.ndarray) -> np.ndarray:
        """dy/dt, shape of ``y`` (d, n)."""
        self.stats["force_evaluations"] += y.shape[1]
        return self.model.rates(y, self.failed, self.held, self.batch)

    def event_margins(self, y: np.ndarray, kinds: frozenset[int] | None = None) -> np.ndarray:
        """The event margins (:meth:`ImpactModel.event_margins`), shape (events, n); only
        the rows ``kinds`` if given."""
        return self.model.event_margins(y, self.failed, self.held, self.batch, kinds)

    def branch_margins(self, y: np.ndarray) -> np.ndarray:
        """The branch surfaces of the force (:meth:`ImpactModel.branch_margins`)."""
        return self.model.branch_margins(y, self.failed, self.batch)

    def at_rest(self, y: np.ndarray) -> np.ndarray:
        """Which scenes are at rest at ``y`` (the embedment rule,
        :meth:`ImpactModel.rest_margin`)."""
        return self.model.rest_margin(y[SPEED], self.batch) >= 0.0
