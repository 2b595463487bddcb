"""Outcome probabilities along impact speed, along obliquity, or over the (speed,
obliquity) plane: the same samples of the other uncertain inputs at every point (common
random numbers, so that the curves are smooth in the point and their differences are
the model's, not the sampling's), each point's probabilities with exact binomial
intervals."""

from __future__ import annotations

from concurrent.futures import Executor
from typing import Any

import attrs
import numpy as np

from ..model.batch import SceneBatch
from ..model.results import BatchResult
from ..registry.plugin_registry import PluginRegistry
from ..run.simulation import Simulation
from .propagation import OUTCOMES, binomial_intervals, sample_inputs, scenes
from .spec import UncertaintySpec, UncertaintySpecError

#: The most scenes a curve or map runs (samples × points) unless asked otherwise.
MAX_CURVE_SCENES = 5_000_000


@attrs.frozen
class OutcomeGrid:
    """The probability of each outcome at each (speed [m/s], obliquity [deg]) point of
    the grid (shape: speeds × obliquities), from the same samples at every point."""

    spec: UncertaintySpec
    speeds_m_s: np.ndarray
    obliquities_deg: np.ndarray
    counts: dict[str, np.ndarray]
    samples: int
    confidence: float = 0.95

    def probabilities(self) -> dict[str, np.ndarray]:
        return {name: count / self.samples for name, count in self.counts.items()}

    def intervals(self) -> dict[str, tuple[np.ndarray, np.ndarray]]:
        """Each probability's exact binomial interval at every point (low, high)."""
        return {
            name: binomial_intervals(count, self.samples, self.confidence)
            for name, count in self.counts.items()
        }

    def to_json(self) -> dict[str, Any]:
        intervals = self.intervals()
        return {
            "samples": self.samples,
            "confidence": self.confidence,
            "speeds_m_s": self.speeds_m_s.tolist(),
            "obliquities_deg": self.obliquities_deg.tolist(),
            "probabilities": {k: v.tolist() for k, v in self.probabilities().items()},
            "intervals": {k: [lo.tolist(), hi.tolist()] for k, (lo, hi) in intervals.items()},
            "spec": self.spec.describe(),
        }


def outcome_grid(
    spec: UncertaintySpec,
    registry: PluginRegistry,
    speeds_m_s: np.ndarray | None = None,
    obliquities_deg: np.ndarray | None = None,
    *,
    simulation: Simulation | None = None,
    executor: Executor | None = None,
    max_scenes: int | None = MAX_CURVE_SCENES,
) -> OutcomeGrid:
    """The outcome probabilities over ``speeds_m_s`` × ``obliquities_deg`` (either None:
    the spec's ``at`` value); an input given a grid takes no distribution."""
    grids = {"speed_m_s": speeds_m_s, "obliquity_deg": obliquities_deg}
    for name, grid in grids.items():
        if grid is None:
            if name not in spec.at:
                raise UncertaintySpecError(f"{spec.source}: {name}: give it in at or a grid")
            grids[name] = np.array([spec.at[name]])
        elif name in spec.inputs:
            raise UncertaintySpecError(
                f"{spec.source}: inputs.{name}: a grid of it takes no distribution"
            )
    speeds, obliquities = (np.asarray(grids[k], float) for k in ("speed_m_s", "obliquity_deg"))
    points = speeds.size * obliquities.size
    if max_scenes is not None and points * spec.samples > max_scenes:
        raise UncertaintySpecError(
            f"{spec.source}: {spec.samples:,} samples at {points:,} points are "
            f"{points * spec.samples:,} scenes, more than {max_scenes:,}"
        )
    if simulation is None:
        simulation = Simulation.from_names(failure=spec.failure, registry=registry)
    inputs = sample_inputs(spec)
    parts = [
        scenes(attrs.evolve(spec, at={**spec.at, "speed_m_s": float(v), "obliquity_deg": float(o)}),
               inputs, registry)
        for v in speeds
        for o in obliquities
    ]  # fmt: skip
    # every point's samples in one batch, point-major
    result: BatchResult = simulation.run_batch(SceneBatch.concat(parts), executor=executor)
    outcome = result.outcome.reshape(speeds.size, obliquities.size, spec.samples)
    counts = {name: np.sum(outcome == code, axis=2) for name, code in OUTCOMES.items()}
    return OutcomeGrid(spec, speeds, obliquities, counts, spec.samples)
