"""The Integrator interface and the recorder integrators fill their results with."""

from __future__ import annotations

from abc import ABC, abstractmethod
from typing import ClassVar

import numpy as np

from .batch import SceneBatch
from .model import ImpactModel
from .results import RESULT_FIELDS, TRAJECTORY_FIELDS, BatchResult


class Integrator(ABC):
    """Advances a batch of scenes from first contact to their outcomes.

    :meth:`run` is the template: it binds the model to the batch (every per-scene
    constant computed once), then calls :meth:`_integrate`, which a subclass implements.
    The state of a scene is its penetration P [m], lateral displacement Y [m], obliquity
    θ [rad] and speed V [m/s], starting at (0, 0, θs, Vs); the equations of motion are
    dV/dt = −drag/m, dθ/dt = lift/(m V), dP/dt = V cos θ, dY/dt = V sin θ (eqs 25–30),
    with drag and lift from :meth:`ImpactModel.forces`.

    An integrator must honour the model's events: failure onset when P reaches
    ``batch.onset_penetration``; the outcome tests of :meth:`ImpactModel.classify`;
    rest when V reaches ``batch.rest_speed``; θ held at :attr:`ImpactModel.MAX_OBLIQUITY`.
    It must work on whole arrays (no Python loop over scenes) and may drop finished
    scenes from its working set. It reports through a :class:`ResultRecorder`.
    """

    name: ClassVar[str]
    version: ClassVar[str] = "1"

    def run(
        self, model: ImpactModel, batch: SceneBatch, *, record_trajectory: bool = False
    ) -> BatchResult:
        """Integrate every scene of ``batch`` to its outcome."""
        recorder = ResultRecorder(batch.size, record_trajectory, model.failure.state_names)
        if batch.size:
            self._integrate(model, model.bind(batch), recorder)
        return recorder.result()

    @abstractmethod
    def _integrate(self, model: ImpactModel, batch: SceneBatch, recorder: ResultRecorder) -> None:
        """Integrate the (bound) batch, reporting through ``recorder``."""

    def settings(self) -> dict[str, object]:
        """The integrator's settings, for output and archives (default: none)."""
        return {}


class ResultRecorder:
    """Collects per-scene results and trajectory samples as an integrator produces them.

    Scenes are addressed by their index in the original batch, so an integrator can
    shrink its working arrays as scenes finish.
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
        self.stats: dict[str, float] = {"steps": 0, "force_evaluations": 0}

    def sample(
        self,
        scene: np.ndarray,
        time: np.ndarray,
        penetration: np.ndarray,
        lateral: np.ndarray,
        obliquity: np.ndarray,
        speed: np.ndarray,
        failure_state: np.ndarray | None = None,
        failed: np.ndarray | None = None,
    ) -> None:
        """Record the state of ``scene`` s if trajectories were asked for.

        ``failure_state`` has shape (len(failure_state_names), n); where ``failed`` is
        False it means nothing and is recorded as NaN.
        """
        if not self.record_trajectory:
            return
        columns = [time, penetration, lateral, obliquity, speed]
        if self.failure_state_names:
            mask = np.ones(np.shape(time), bool) if failed is None else failed
            columns.extend(np.where(mask, failure_state, np.nan))
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
        """The batch's results; trajectories as contiguous ragged arrays."""
        trajectory = counts = None
        if self.record_trajectory:
            names = [*TRAJECTORY_FIELDS, *(f"failure_{n}" for n in self.failure_state_names)]
            if self._samples:
                stacked = [np.concatenate(part) for part in zip(*self._samples, strict=True)]
            else:
                stacked = [np.zeros(0, dtype=int)] + [np.zeros(0)] * len(names)
            scene, *values = stacked
            order = np.lexsort((values[0], scene))  # by scene, then by time
            trajectory = {k: x[order] for k, x in zip(names, values, strict=True)}
            counts = np.bincount(scene, minlength=self.size)
        return BatchResult(dict(self.columns), trajectory, counts, dict(self.stats))
