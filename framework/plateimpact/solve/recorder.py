"""The recorder the driver fills with per-scene results and trajectory samples."""

from __future__ import annotations

import numpy as np

from ..model.impact import KINEMATIC_STATE
from ..model.ragged import Ragged
from ..model.results import RESULT_FIELDS, TRAJECTORY_FIELDS, BatchResult


class ResultRecorder:
    """Collects per-scene results and trajectory samples as the driver produces them.

    Scenes are addressed by their index in the original batch, so the driver can shrink
    its working arrays as scenes finish.
    """

    def __init__(
        self, size: int, record_trajectory: bool, failure_state_names: tuple[str, ...] = ()
    ) -> None:
        self.size = size
        self.record_trajectory = record_trajectory
        self.failure_state_names = failure_state_names
        self.columns: dict[str, np.ndarray] = {
            name: np.full(size, np.nan) for name in RESULT_FIELDS
        }
        self.columns["outcome"] = np.zeros(size, dtype=np.int8)
        self.columns["plate_failed"] = np.zeros(size, dtype=bool)
        self._samples: list[tuple[np.ndarray, ...]] = []
        self.stats: dict[str, int] = {
            "steps": 0,
            "force_evaluations": 0,
            "accepted_steps": 0,
            "rejected_steps": 0,
            "compiled_scenes": 0,
        }

    def sample(
        self, scene: np.ndarray, time: np.ndarray, y: np.ndarray, failed: np.ndarray
    ) -> None:
        """Record the states ``y`` (d, n: P, Y, θ, V, then the failure state) of scenes
        ``scene`` at ``time`` [s], if trajectories were asked for. The failure state means
        nothing where ``failed`` is False and is recorded as NaN there."""
        if not self.record_trajectory:
            return
        state = np.where(failed, y[KINEMATIC_STATE:], np.nan)
        columns = [time, *y[:KINEMATIC_STATE], *state]
        self._samples.append((scene.copy(), *(np.array(c, dtype=float) for c in columns)))

    def failed(
        self, scene: np.ndarray, time: np.ndarray, penetration: np.ndarray, lateral: np.ndarray
    ) -> None:
        """Record where and when the plate of ``scene`` failed."""
        self.columns["plate_failed"][scene] = True
        self.columns["failure_time"][scene] = time
        self.columns["failure_penetration"][scene] = penetration
        self.columns["failure_lateral"][scene] = lateral

    def finish(
        self,
        scene: np.ndarray,
        outcome: np.ndarray,
        exit_speed: np.ndarray,
        exit_obliquity: np.ndarray,
        contact_time: np.ndarray,
        max_penetration: np.ndarray,
    ) -> None:
        """Record the outcome of the finished ``scene`` s. The exit obliquity is the angle
        from the plate normal, >= 0 (a path that ends just across the normal, θ < 0, is
        the mirror image of one that does not)."""
        c = self.columns
        c["outcome"][scene] = outcome
        c["exit_speed"][scene] = exit_speed
        c["exit_obliquity"][scene] = np.abs(exit_obliquity)
        c["contact_time"][scene] = contact_time
        c["max_penetration"][scene] = max_penetration

    def result(self) -> BatchResult:
        """The batch's results; trajectories as a ragged array, one row per scene."""
        trajectory = None
        if self.record_trajectory:
            names = [*TRAJECTORY_FIELDS, *(f"failure_{n}" for n in self.failure_state_names)]
            if self._samples:
                scene, *values = (np.concatenate(part) for part in zip(*self._samples, strict=True))
            else:
                scene, values = np.zeros(0, dtype=int), [np.zeros(0)] * len(names)
            columns = dict(zip(names, values, strict=True))
            trajectory = Ragged.from_samples(self.size, scene, columns, order_by="time")
        return BatchResult(dict(self.columns), trajectory, dict(self.stats))
