"""The distributions of the ballistic and ricochet limits: both limits found for every
sample of the uncertain inputs at each obliquity (uncertainty.limit_search: the limits
finder, every sample's line in the same batches), and from them the whole probabilistic
velocity-response curves without a run per speed,

    P(perforation | V) = P(V_bl < V),    P(ricochet | V) = P(V_rl > V),

with V10/V50/V90 of each limit and distribution-free (order-statistic) intervals, reported
with the keys of ``plateimpact v50`` (``v50_m_s``, ``v50_ci_m_s``, ``sigma_m_s``, ...)."""

from __future__ import annotations

import math
from collections.abc import Sequence
from concurrent.futures import Executor
from typing import Any

import attrs
import numpy as np
from scipy import stats

from ..base.errors import ParameterError
from ..registry.plugin_registry import PluginRegistry
from ..run.simulation import Simulation
from .limit_search import RESOLUTION, SPEEDS, TOLERANCE, line_limits, sample_scenes
from .propagation import binomial_intervals, sample_inputs
from .spec import UncertaintySpec

#: The quantiles reported, by the names ``plateimpact v50`` gives them: V_p is the speed
#: below which a fraction p of the samples' limits lie.
LEVELS = {"v50": 0.5, "v10": 0.1, "v90": 0.9}
#: The two limits: what a limit outside the range means, below its start and beyond its
#: end (the keys of the counts).
OUTSIDE = {
    "ballistic": ("perforates_at_every_speed", "perforates_at_no_speed"),
    "ricochet": ("ricochets_at_no_speed", "ricochets_at_every_speed"),
}


def order_statistic_quantile(
    values: np.ndarray, level: float, confidence: float
) -> dict[str, float]:
    """The ``level`` quantile of ``values`` [m/s] (±inf allowed) and a distribution-free
    interval: the order statistics between which the true quantile lies with probability
    >= ``confidence`` (binomial counts of the samples below it)."""
    ordered = np.sort(values)
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


def _finite(value: float) -> float | None:
    """A speed for JSON: None where it is outside the range (±inf)."""
    return value if math.isfinite(value) else None


@attrs.frozen(eq=False)
class SampledLimits:
    """The ballistic and ricochet limits [m/s] of each sample at ``obliquity`` [rad]
    (±inf outside the range: uncertainty.limit_search), found over ``speeds`` [m/s] to
    ``tolerance`` [m/s] with a scan every ``resolution`` [m/s]; ``inputs``: the samples
    [user units]; ``perforation_gaps``, ``ricochet_gaps``: samples whose bands are not
    one run either side of the limit; ``scenes``, ``passes``: the whole search's (all its
    obliquities')."""

    spec: UncertaintySpec
    obliquity: float
    inputs: dict[str, np.ndarray]
    ballistic: np.ndarray
    speeds: tuple[float, float]
    tolerance: float
    resolution: float
    ricochet: np.ndarray = attrs.field(kw_only=True)
    perforation_gaps: int = attrs.field(default=0, kw_only=True)
    ricochet_gaps: int = attrs.field(default=0, kw_only=True)
    scenes: int = attrs.field(default=0, kw_only=True)
    passes: int = attrs.field(default=0, kw_only=True)

    def limit(self, name: str) -> np.ndarray:
        """The samples' ``ballistic`` or ``ricochet`` limit [m/s]."""
        if name not in OUTSIDE:
            raise ParameterError(
                "limit", f"limit must be one of {', '.join(OUTSIDE)}, got {name!r}"
            )
        return np.asarray(getattr(self, name))

    def perforation_curve(
        self, speeds: np.ndarray, confidence: float = 0.95
    ) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """P(perforation | V) = P(V_bl < V) at each of ``speeds`` [m/s], with its exact
        binomial interval (low, high)."""
        counts = np.array([int(np.sum(self.ballistic < v)) for v in np.asarray(speeds)])
        return (
            counts / self.ballistic.size,
            *binomial_intervals(counts, self.ballistic.size, confidence),
        )

    def ricochet_curve(
        self, speeds: np.ndarray, confidence: float = 0.95
    ) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """P(ricochet | V) = P(V_rl > V) at each of ``speeds`` [m/s], with its exact
        binomial interval (low, high)."""
        counts = np.array([int(np.sum(self.ricochet > v)) for v in np.asarray(speeds)])
        return (
            counts / self.ricochet.size,
            *binomial_intervals(counts, self.ricochet.size, confidence),
        )

    def quantile(
        self, level: float, confidence: float = 0.95, limit: str = "ballistic"
    ) -> dict[str, float]:
        """V_level [m/s] of the ``limit`` (V50: level 0.5), and a distribution-free
        interval: the order statistics between which the true quantile lies with
        probability >= confidence. ±inf where it is outside the range."""
        return order_statistic_quantile(self.limit(limit), level, confidence)

    def report(self, limit: str, confidence: float = 0.95) -> dict[str, Any]:
        """V10, V50, V90 of the ``limit`` with their intervals and its sigma, with the
        keys of ``plateimpact v50``; a quantile or an interval end outside the range is
        None (JSON null), and ``*_outside_range`` says on which side; the samples
        outside the range are counted by what they mean (:data:`OUTSIDE`)."""
        values = self.limit(limit)
        below, beyond = OUTSIDE[limit]
        within = np.isfinite(values)
        out: dict[str, Any] = {
            "samples": int(values.size),
            "within_range": int(np.sum(within)),
            below: int(np.sum(values == -math.inf)),
            beyond: int(np.sum(values == math.inf)),
            "gaps": self.perforation_gaps if limit == "ballistic" else self.ricochet_gaps,
            # the spread of the limit's distribution: only when every sample has one
            "sigma_m_s": float(values.std(ddof=1)) if within.all() and values.size > 1 else None,
            "confidence": confidence,
        }
        for key, level in LEVELS.items():
            q = self.quantile(level, confidence, limit)
            point = q["speed_m_s"]
            out[f"{key}_m_s"] = _finite(point)
            out[f"{key}_ci_m_s"] = [_finite(q["low_m_s"]), _finite(q["high_m_s"])]
            out[f"{key}_outside_range"] = (
                None if math.isfinite(point) else "below" if point < 0 else "beyond"
            )
        return out

    def to_json(self, confidence: float = 0.95) -> dict[str, Any]:
        """Both limits' reports at this obliquity (JSON-ready: no NaN or infinity)."""
        return {
            "obliquity_deg": float(f"{math.degrees(self.obliquity):.12g}"),
            "ballistic_limit": self.report("ballistic", confidence),
            "ricochet_limit": self.report("ricochet", confidence),
        }

    def search(self) -> dict[str, Any]:
        """How the limits were found (JSON-ready)."""
        return {
            "speeds_m_s": list(self.speeds),
            "tolerance_m_s": self.tolerance,
            "resolution_m_s": self.resolution,
            "scenes": self.scenes,
            "passes": self.passes,
        }


def sampled_limits_at(
    spec: UncertaintySpec,
    registry: PluginRegistry,
    obliquities_deg: Sequence[float] | np.ndarray,
    *,
    speeds: tuple[float, float] = SPEEDS,
    tolerance: float = TOLERANCE,
    resolution: float = RESOLUTION,
    simulation: Simulation | None = None,
    executor: Executor | None = None,
) -> tuple[SampledLimits, ...]:
    """The ballistic and ricochet limits of every sample of ``spec``'s inputs at each of
    ``obliquities_deg`` [deg], in one search (the same samples at every obliquity).
    The speed and the obliquity cannot be uncertain here: the limits are speeds, found
    at the obliquities given. ``executor``: where the finder's batches run (a process
    pool, a Dask client's executor), with the same results bit for bit."""
    refused = {"speed_m_s": "the limits are speeds",
               "obliquity_deg": "the limits are found at the obliquities given"}  # fmt: skip
    for name, why in refused.items():
        if name in spec.inputs:
            raise ParameterError(name, f"{why}: give {name} no distribution")
    angles = np.radians(np.atleast_1d(np.asarray(obliquities_deg, dtype=float)))
    if simulation is None:
        simulation = Simulation.from_names(failure=spec.failure, registry=registry)
    inputs = sample_inputs(spec)
    base = sample_scenes(spec, inputs, registry, speeds)
    n = spec.samples
    found = line_limits(
        base, np.tile(np.arange(n), angles.size), np.repeat(angles, n), simulation,
        speeds=speeds, tolerance=tolerance, resolution=resolution, executor=executor,
    )  # fmt: skip
    out = []
    for k, angle in enumerate(angles):
        mine = slice(k * n, (k + 1) * n)
        out.append(
            SampledLimits(
                spec,
                float(angle),
                inputs,
                found.ballistic[mine],
                speeds,
                tolerance,
                resolution,
                ricochet=found.ricochet[mine],
                perforation_gaps=int(found.perforation_gaps[mine].sum()),
                ricochet_gaps=int(found.ricochet_gaps[mine].sum()),
                scenes=found.scenes,
                passes=found.passes,
            )  # fmt: skip
        )
    return tuple(out)


def sampled_limits(
    spec: UncertaintySpec, registry: PluginRegistry, obliquity_deg: float, **options: Any
) -> SampledLimits:
    """:func:`sampled_limits_at` at one obliquity [deg]."""
    return sampled_limits_at(spec, registry, [obliquity_deg], **options)[0]
