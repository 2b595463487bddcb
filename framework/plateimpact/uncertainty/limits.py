"""The distribution of the ballistic limit: the limit found for every sample of the
uncertain inputs (the limits finder's bracketing, all samples' lines in the same batches),
and from it the whole probabilistic velocity-response curve P(perforation | V) =
P(V_bl < V) without a run per speed, and its V10/V50/V90 with distribution-free
(order-statistic) intervals."""

from __future__ import annotations

import math
from typing import Any

import attrs
import numpy as np
from scipy import stats

from ..base.errors import ParameterError
from ..limits.bracketing import locate
from ..limits.chunked import run_chunked
from ..limits.lines import SPEED
from ..limits.plate_limits import line_of
from ..limits.regimes import regime_codes
from ..model.results import Outcome
from ..registry.plugin_registry import PluginRegistry
from ..run.simulation import Simulation
from .propagation import sample_inputs, scenes
from .spec import UncertaintySpec

#: The defaults of a sampled limit: the speed range [m/s], each limit's bracket [m/s],
#: and the scan's step [m/s] (a band narrower than it may be missed: coarser than the
#: limits command's 1 m/s, since a limit is found for every sample).
SPEEDS, TOLERANCE, RESOLUTION = (50.0, 2000.0), 0.1, 20.0


@attrs.frozen
class SampledLimits:
    """The ballistic limit [m/s] of each sample at ``obliquity`` [rad]: −inf where the
    whole range perforates, +inf where none of it does; ``inputs``: the samples [user
    units]."""

    spec: UncertaintySpec
    obliquity: float
    inputs: dict[str, np.ndarray]
    ballistic: np.ndarray
    speeds: tuple[float, float]
    tolerance: float
    resolution: float

    def perforation_curve(
        self, speeds: np.ndarray, confidence: float = 0.95
    ) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """P(perforation | V) = P(V_bl < V) at each of ``speeds`` [m/s], with its exact
        binomial interval (low, high)."""
        n = self.ballistic.size
        counts = np.array([int(np.sum(self.ballistic < v)) for v in np.asarray(speeds)])
        low, high = np.empty(counts.size), np.empty(counts.size)
        for i, k in enumerate(counts):
            ci = stats.binomtest(int(k), n).proportion_ci(confidence, method="exact")
            low[i], high[i] = ci.low, ci.high
        return counts / n, low, high

    def quantile(self, level: float, confidence: float = 0.95) -> dict[str, float]:
        """V_level [m/s] (V50: level 0.5), and a distribution-free interval: the order
        statistics between which the true quantile lies with probability >= confidence."""
        ordered = np.sort(self.ballistic)
        n = ordered.size
        point = float(np.quantile(ordered, level, method="inverted_cdf"))
        tail = (1.0 - confidence) / 2.0
        lo = int(stats.binom.ppf(tail, n, level))  # P(X < lo) <= tail
        hi = int(stats.binom.ppf(1.0 - tail, n, level)) + 1
        return {
            "speed_m_s": point,
            "low_m_s": float(ordered[lo - 1]) if lo >= 1 else -math.inf,
            "high_m_s": float(ordered[hi - 1]) if hi <= n else math.inf,
        }

    def to_json(self) -> dict[str, Any]:
        """V10, V50 and V90 with their intervals, and how the limits were found."""
        finite = self.ballistic[np.isfinite(self.ballistic)]
        return {
            "obliquity_deg": math.degrees(self.obliquity),
            "samples": int(self.ballistic.size),
            "beyond_range": int(np.sum(self.ballistic == math.inf)),
            "below_range": int(np.sum(self.ballistic == -math.inf)),
            "mean_m_s": float(finite.mean()) if finite.size else None,
            "sd_m_s": float(finite.std(ddof=1)) if finite.size > 1 else None,
            **{f"V{round(100 * q)}": self.quantile(q) for q in (0.1, 0.5, 0.9)},
            "speeds_m_s": list(self.speeds),
            "tolerance_m_s": self.tolerance,
            "resolution_m_s": self.resolution,
        }


def sampled_limits(
    spec: UncertaintySpec,
    registry: PluginRegistry,
    obliquity_deg: float,
    *,
    speeds: tuple[float, float] = SPEEDS,
    tolerance: float = TOLERANCE,
    resolution: float = RESOLUTION,
    simulation: Simulation | None = None,
) -> SampledLimits:
    """The ballistic limit of every sample of ``spec``'s inputs at ``obliquity_deg``
    [deg]. The impact speed cannot be uncertain here: the limit is a speed."""
    if "speed_m_s" in spec.inputs:
        raise ParameterError(
            "speed_m_s", "the ballistic limit is a speed: give speed_m_s no distribution"
        )
    if simulation is None:
        simulation = Simulation.from_names(failure=spec.failure, registry=registry)
    obliquity = math.radians(obliquity_deg)
    inputs = sample_inputs(spec)
    nominal = attrs.evolve(spec, at={**spec.at, "speed_m_s": speeds[0]})
    base = scenes(nominal, inputs, registry)

    def evaluate(line: np.ndarray, x: np.ndarray) -> np.ndarray:
        def batch_of(index: np.ndarray) -> Any:
            return base.take(line[index]).with_columns(
                impact_speed=x[index], impact_obliquity=np.full(index.size, obliquity)
            )

        codes = np.empty(x.size, dtype=np.int64)
        for where, result in run_chunked(simulation, batch_of, x.size):
            codes[where] = regime_codes(result)
        return codes

    n = spec.samples
    found = locate(evaluate, np.full(n, speeds[0]), np.full(n, speeds[1]), resolution, tolerance)
    ballistic = np.empty(n)
    for i in range(n):
        line = line_of(found, i, SPEED, obliquity, speeds)
        limit = line.ballistic_limit
        if limit is None:
            perforates = line.bands[-1].regime.outcome is Outcome.PERFORATION
            limit = -math.inf if perforates else math.inf
        ballistic[i] = limit
    return SampledLimits(spec, obliquity, inputs, ballistic, speeds, tolerance, resolution)
