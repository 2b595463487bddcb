"""Profile-likelihood (likelihood-ratio) confidence intervals of V50, V10, V90 and σ.

The interval of a parameter θ at confidence c is the set of θ whose profile deviance
2 (min −log L given θ − min −log L) is at most χ²₁(c), the c-quantile of chi-square with
one degree of freedom (Wilks). The other parameter (the nuisance) is maximised out by
scipy.optimize for each θ: with the p-quantile V_p = V50 + s F⁻¹(p) fixed at t, z =
b (x − t) + F⁻¹(p) is linear in b = 1/s ≥ 0; with the scale fixed, z = x/s + a is linear
in a; both one-dimensional problems are convex. Each end is bracketed by stepping out
from the estimate, doubling the step, then found by Brent's method. Unlike a Wald
interval (estimate ± 1.96 standard errors) the ends need not be symmetric, which they
are not for σ or for few shots; and an end beyond the reach searched is reported as None
(the data do not bound it), as is a speed's end below 0 m/s.
"""

from __future__ import annotations

import math
from collections.abc import Callable

from scipy import optimize, stats

from .likelihood import GoNoGo, LikelihoodMaximum, Link

#: An interval [low, high]; None for an end the data do not bound.
Interval = tuple[float | None, float | None]
#: How far an end is searched for: a speed within this many standard deviations of the
#: shot speeds from the estimate, and above 0 m/s; a scale within this factor of the
#: estimate's.
SPEED_REACH, SCALE_REACH = 100.0, 1e3
#: The nuisance b = 1/s is searched in [0, this × the estimate's b].
SLOPE_REACH = 1e3
#: Ends located to this [x units: standard deviations of the shot speeds; or log scale].
END_TOLERANCE = 1e-9


def threshold(confidence: float) -> float:
    """The deviance at an interval's end: χ²₁ at ``confidence``."""
    return float(stats.chi2.ppf(confidence, 1))


def quantile_profile(
    shots: GoNoGo, link: Link, p: float, best: LikelihoodMaximum
) -> Callable[[float], float]:
    """−log L maximised over the scale, with the p-quantile fixed at t [x units]."""
    q = link.quantile(p)
    slope_bound = SLOPE_REACH / best.scale

    def at(t: float) -> float:
        def value(slope: float) -> float:
            return shots.negative_log_likelihood(slope * (shots.x - t) + q, link)

        found = optimize.minimize_scalar(
            value, bounds=(0.0, slope_bound), method="bounded",
            options={"xatol": 1e-9 / best.scale},
        )  # fmt: skip
        return min(float(found.fun), value(0.0))

    return at


def scale_profile(shots: GoNoGo, link: Link, best: LikelihoodMaximum) -> Callable[[float], float]:
    """−log L maximised over the location, with log(scale) fixed [log x units]."""

    def at(log_scale: float) -> float:
        slope = math.exp(-log_scale)

        def value(offset: float) -> float:
            return shots.negative_log_likelihood(slope * shots.x + offset, link)

        start = -slope * best.location
        found = optimize.minimize_scalar(value, bracket=(start, start + 1.0), method="brent")
        return float(found.fun)

    return at


def interval_end(
    deviance: Callable[[float], float], start: float, step: float, limit: float
) -> float | None:
    """Where ``deviance`` (< 0 at ``start``) crosses 0, stepping out from ``start`` by
    ``step`` (signed), doubling, as far as ``limit``; None if it does not before."""
    direction = math.copysign(1.0, step)
    if (limit - start) * direction <= 0.0:
        return None
    inner, outer = start, start + step
    while (outer - limit) * direction < 0.0 and deviance(outer) < 0.0:
        inner, outer = outer, start + 2.0 * (outer - start)
    if (outer - limit) * direction >= 0.0:
        outer = limit
        if deviance(outer) < 0.0:
            return None
    return float(optimize.brentq(deviance, inner, outer, xtol=END_TOLERANCE))


def _interval(
    profile: Callable[[float], float], best: LikelihoodMaximum, centre: float, step: float,
    limits: tuple[float, float], confidence: float,
) -> tuple[float | None, float | None]:  # fmt: skip
    level = best.negative_log_likelihood + 0.5 * threshold(confidence)

    def deviance(theta: float) -> float:
        return 2.0 * (profile(theta) - level)

    return (
        interval_end(deviance, centre, -step, limits[0]),
        interval_end(deviance, centre, step, limits[1]),
    )


def profile_intervals(
    shots: GoNoGo, link: Link, best: LikelihoodMaximum, confidence: float, levels: dict[str, float]
) -> dict[str, Interval]:
    """The profile intervals [m/s] of the quantiles ``levels`` (name -> p) and of
    ``sigma`` (the standard deviation of F)."""
    found: dict[str, Interval] = {}
    for name, p in levels.items():
        centre = best.location + best.scale * link.quantile(p)
        # no further than SPEED_REACH either side, and no speed below 0 m/s
        limits = (max(centre - SPEED_REACH, -shots.centre / shots.spread), centre + SPEED_REACH)
        low, high = _interval(
            quantile_profile(shots, link, p, best), best, centre, best.scale, limits, confidence
        )
        found[name] = (
            None if low is None else shots.speed(low),
            None if high is None else shots.speed(high),
        )
    log_scale = math.log(best.scale)
    reach = math.log(SCALE_REACH)
    log_low, log_high = _interval(
        scale_profile(shots, link, best), best, log_scale, 0.25,
        (log_scale - reach, log_scale + reach), confidence,
    )  # fmt: skip
    per_x = shots.spread * link.sigma_per_scale
    found["sigma"] = (
        None if log_low is None else per_x * math.exp(log_low),
        None if log_high is None else per_x * math.exp(log_high),
    )
    return found


__all__ = ["Interval", "profile_intervals", "threshold"]
