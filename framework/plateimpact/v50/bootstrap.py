"""Parametric-bootstrap percentile intervals of V50, V10, V90 and σ.

Each resample keeps the shots' speeds and weights and draws their outcomes again from
the fitted curve (a shot of weight w, w identical shots: a binomial count of
perforations among them); the fit is repeated on it, and the interval at confidence c is
the pair of order statistics at (1 − c)/2 and (1 + c)/2 of what the resamples give.

A resample whose likelihood has no finite maximum enters as the limit the likelihood
climbs towards, not left out (leaving it out would narrow the interval exactly where
the data are thin):

* outcomes separated by a speed, perforations above (separated): a step at the middle
  of the gap, σ = 0 and every quantile there;
* no rise of perforation with speed (one outcome only, perforations all below the
  non-perforations, or a best slope <= 0): the best curve that does not fall with speed,
  the flat curve P = the share perforated, σ = ∞ and the p-quantile at −∞ if that share
  exceeds p, +∞ if it falls short (undefined, and left out, if equal).

Every other resample has a maximum, and is fitted by the same solver as the shots
(plateimpact.v50.solver, with its fallback); one that no solver fits (none is known) is
left out and counted as ``failed``, never read as flat.

An interval end at ±∞, or a speed's end at or below 0 m/s, is reported as None
(unbounded); a quantity left out of more resamples than an interval's tail holds gets no
interval.
"""

from __future__ import annotations

import math

import attrs
import numpy as np

from ..base.errors import V50Error
from .likelihood import Link, prepared
from .profile import Interval
from .solver import maximum


@attrs.frozen
class BootstrapIntervals:
    """The intervals by name (``sigma`` and the quantiles), and how many resamples were
    separated (step curves), flat, or failed (no solver converged: left out)."""

    intervals: dict[str, Interval]
    separated: int
    flat: int
    failed: int


def _resample_values(
    speed: np.ndarray, perforated: np.ndarray, weight: np.ndarray, link: Link,
    levels: dict[str, float],
) -> tuple[dict[str, float], str]:  # fmt: skip
    """What one resample gives [m/s], and whether it was ``fitted``, ``separated``,
    ``flat`` or ``failed``."""
    go, no_go = (weight > 0) & perforated, (weight > 0) & ~perforated
    if go.any() and no_go.any():
        lowest_go, highest_no_go = speed[go].min(), speed[no_go].max()
        if highest_no_go <= lowest_go:
            middle = 0.5 * float(lowest_go + highest_no_go)
            return {**dict.fromkeys(levels, middle), "sigma": 0.0}, "separated"
        if speed[go].max() > speed[no_go].min():  # else perforations all below: flat
            shots = prepared(speed, perforated, weight)
            try:
                best = maximum(shots, link, "bootstrap resample")
            except V50Error:  # no solver converged: left out, not read as anything
                return {**dict.fromkeys(levels, math.nan), "sigma": math.nan}, "failed"
            if best.slope > 0.0:
                found = {
                    name: shots.speed(best.location + best.scale * link.quantile(p))
                    for name, p in levels.items()
                }
                sigma = shots.spread * best.scale * link.sigma_per_scale
                return {**found, "sigma": sigma}, "fitted"
    share = float(weight[perforated].sum() / weight.sum())
    flat = {name: -math.inf if share > p else math.inf if share < p else math.nan
            for name, p in levels.items()}  # fmt: skip
    return {**flat, "sigma": math.inf}, "flat"


def bootstrap_intervals(
    speed: np.ndarray, perforated: np.ndarray, weight: np.ndarray, link: Link,
    fitted: tuple[float, float], resamples: int, rng: np.random.Generator | int | None,
    confidence: float, levels: dict[str, float],
) -> BootstrapIntervals:  # fmt: skip
    """Percentile intervals at ``confidence`` from ``resamples`` parametric resamples of
    the shots (speed [m/s], perforated, weight) under the curve ``fitted`` = (V50, s)
    [m/s], for ``sigma`` and the quantiles ``levels`` (name -> p)."""
    if resamples == 0:
        return BootstrapIntervals({}, 0, 0, 0)
    used = weight > 0
    v, w = speed[used], weight[used]
    v50, scale = fitted
    p = np.exp(link.log_cdf((v - v50) / scale))
    generator = np.random.default_rng(rng)
    if np.all(w == np.round(w)):  # w identical shots: a binomial count of perforations
        goes = generator.binomial(w.astype(np.int64), p, size=(resamples, v.size))
        rows_v, rows_y = np.concatenate([v, v]), np.repeat([True, False], v.size)
        rows_w = np.concatenate([goes, w - goes], axis=1).astype(float)
        draws = [(rows_v, rows_y, row) for row in rows_w]
    else:  # fractional weights: one draw per shot, its weight kept
        outcomes = generator.random((resamples, v.size)) < p
        draws = [(v, row, w) for row in outcomes]
    values: dict[str, list[float]] = {name: [] for name in (*levels, "sigma")}
    kinds = {"fitted": 0, "separated": 0, "flat": 0, "failed": 0}
    for draw in draws:
        found, kind = _resample_values(*draw, link, levels)
        kinds[kind] += 1
        for name, value in found.items():
            values[name].append(value)
    # (1 − 0.95)/2 is 0.025000000000000022 in floating point, which took the order
    # statistic after the one meant (the 26th of 1000, not the 25th): rounded off.
    tail = round(0.5 * (1.0 - confidence), 12)
    intervals: dict[str, Interval] = {}
    for name, column in values.items():
        known = np.asarray(column)[~np.isnan(column)]
        if known.size < (1.0 - tail) * resamples:
            continue  # undefined in more resamples than the tail holds
        low, high = np.quantile(known, [tail, 1.0 - tail], method="inverted_cdf")
        floor = 0.0 if name in levels else -math.inf  # a speed below 0 m/s: unbounded
        intervals[name] = (
            float(low) if math.isfinite(low) and low > floor else None,
            float(high) if math.isfinite(high) and high > floor else None,
        )
    return BootstrapIntervals(intervals, kinds["separated"], kinds["flat"], kinds["failed"])
