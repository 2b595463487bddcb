"""The likelihood of go/no-go shots under P(perforation) = F((v − V50)/s), and its maximum.

Each shot i, at impact speed v_i [m/s] with weight w_i (a frequency: w_i identical
shots), perforated (y_i = 1) or not (y_i = 0). F is symmetric (1 − F(z) = F(−z)), so with
u_i = (2 y_i − 1) z_i the negative log-likelihood is

    −log L = −Σ w_i log F(u_i),   z_i = (v_i − V50)/s

with F = Φ (probit; s is the normal's standard deviation σ) or the logistic CDF
1/(1 + e^−z) (logit; s is its scale, its standard deviation σ = s π/√3). In the linear
form z = β0 + β1 x of a binomial GLM, x = (v − c)/d the speeds centred and scaled, −log L
is convex in (β0, β1) (F is log-concave), so its maximum is unique where it exists;
plateimpact.v50.solver finds it from the exact gradient and Hessian written below.
It exists if and only if the speeds of the two outcomes overlap both ways (the highest
non-perforation is faster than the lowest perforation, and the highest perforation
faster than the lowest non-perforation): otherwise the outcomes are separated by a speed
and the likelihood climbs without bound as the curve steepens into a step there
(quasi-complete separation), which :func:`check_shots` refuses: rising, s → 0; falling,
no ballistic limit at all.
"""

from __future__ import annotations

import math
from collections.abc import Callable

import attrs
import numpy as np
from scipy import special

from ..base.errors import ParameterError, V50Error
from ..storage.shots import Shots

#: The fits, by name.
PROBIT, LOGIT = "probit", "logit"
METHODS = (PROBIT, LOGIT)
#: The label of shots given as arrays, in messages.
SHOTS = "shots"
#: Fewest shots (rounds: weights counted) a fit takes: two parameters and something left
#: over.
MIN_SHOTS = 4
#: The largest weight a row takes (a billion shots): beyond it the sums that the fit and
#: its intervals work with lose their meaning, and the bootstrap's counts their type.
MAX_WEIGHT = 1e9


@attrs.frozen
class Link:
    """F of the model, with what the fit needs of it (all vectorised over z)."""

    name: str
    log_cdf: Callable[[np.ndarray], np.ndarray]  # log F(z)
    hazard: Callable[[np.ndarray], np.ndarray]  # λ(z) = F'(z)/F(z) = d log F/dz
    curvature: Callable[[np.ndarray], np.ndarray]  # −d²log F/dz² = −λ'(z) > 0
    quantile: Callable[[float], float]  # F⁻¹(p)
    sigma_per_scale: float  # the standard deviation of F at s = 1


def _probit_hazard(z: np.ndarray) -> np.ndarray:
    # φ(z)/Φ(z) from logarithms: exact in both tails, where φ and Φ underflow
    return np.exp(-0.5 * z * z - 0.5 * math.log(2 * math.pi) - special.log_ndtr(z))


def _probit_curvature(z: np.ndarray) -> np.ndarray:
    hazard = _probit_hazard(z)
    return hazard * (z + hazard)


LINKS = {
    PROBIT: Link(PROBIT, special.log_ndtr, _probit_hazard, _probit_curvature, special.ndtri, 1.0),
    LOGIT: Link(
        LOGIT,
        lambda z: -np.logaddexp(0.0, -z),
        lambda z: special.expit(-z),
        lambda z: special.expit(z) * special.expit(-z),
        special.logit,
        math.pi / math.sqrt(3.0),
    ),
}


def link_of(method: str) -> Link:
    if method not in LINKS:
        raise ParameterError(
            "method", f"method must be one of {', '.join(METHODS)}, got {method!r}"
        )
    return LINKS[method]


@attrs.frozen(eq=False)
class GoNoGo:
    """Go/no-go shots ready for the likelihood: the speeds centred and scaled,
    x = (v − centre)/spread, the outcome as a sign (+1 perforated, −1 not), weights > 0."""

    x: np.ndarray
    sign: np.ndarray
    weight: np.ndarray
    centre: float  # [m/s]
    spread: float  # [m/s]

    def speed(self, x: float) -> float:
        """A position in x back in m/s."""
        return self.centre + self.spread * x

    def negative_log_likelihood(self, eta: np.ndarray, link: Link) -> float:
        """−log L for the linear predictor η_i = z_i (one value per shot)."""
        return float(-np.sum(self.weight * link.log_cdf(self.sign * eta)))

    def eta_derivatives(self, eta: np.ndarray, link: Link) -> tuple[np.ndarray, np.ndarray]:
        """d(−log L)/dη_i and d²(−log L)/dη_i² per shot."""
        u = self.sign * eta
        return -self.weight * self.sign * link.hazard(u), self.weight * link.curvature(u)


@attrs.frozen
class LikelihoodMaximum:
    """The maximum of the likelihood: z = intercept + slope x, x in the units of GoNoGo;
    for slope > 0, z = (x − location)/scale."""

    intercept: float
    slope: float
    negative_log_likelihood: float
    iterations: int

    @property
    def location(self) -> float:
        return -self.intercept / self.slope

    @property
    def scale(self) -> float:
        return 1.0 / self.slope


def check_arrays(
    speed: object, perforated: object, weight: object | None
) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """The shots as float speeds [m/s] (finite, > 0), bools and weights (finite, >= 0)."""
    v = np.asarray(speed, dtype=float).reshape(-1)
    y = np.asarray(perforated).reshape(-1)
    w = np.ones(v.size) if weight is None else np.asarray(weight, dtype=float).reshape(-1)
    if y.size != v.size or w.size != v.size:
        raise ParameterError(
            "perforated",
            f"impact_speed, perforated and weight must have one value per shot, got "
            f"{v.size}, {y.size} and {w.size}",
        )
    if not np.all(np.isfinite(v) & (v > 0)):
        raise ParameterError("impact_speed", "impact speeds must be finite and > 0 m/s")
    if not np.isin(y, (0, 1)).all():
        raise ParameterError("perforated", "perforated must be true/false (1/0) per shot")
    if not np.all((w >= 0) & (w <= MAX_WEIGHT)):  # NaN fails too
        raise ParameterError(
            "weight", f"weights must be in [0, {MAX_WEIGHT:g}] (the shots a row stands for)"
        )
    return v, y.astype(bool), w


def go_no_go(
    speed: np.ndarray | Shots, perforated: object, weight: object | None, label: str
) -> tuple[np.ndarray, np.ndarray, np.ndarray, str]:
    """Speeds [m/s], outcomes and weights as :func:`check_arrays` gives them, and the
    shots' label: from the arrays, or from :class:`~plateimpact.Shots` given alone (at one
    obliquity: their ``perforated`` and ``weight``, labelled by their file unless
    ``label`` is given)."""
    if isinstance(speed, Shots):
        if perforated is not None or weight is not None:
            raise ParameterError(
                "perforated",
                "give Shots alone (their perforated and weight are used), or speed, "
                "perforated and weight as arrays",
            )
        shots = speed.at_one_obliquity("a V50")
        found = check_arrays(shots.impact_speed, shots.perforated, shots.weight)
        return (*found, shots.source if label == SHOTS else label)
    if perforated is None:
        raise ParameterError("perforated", "perforated is needed with speeds: one per shot")
    return (*check_arrays(speed, perforated, weight), label)


def rounds(weight: np.ndarray) -> int | float:
    """How many shots the weights stand for (their sum): a whole number when they are."""
    total = float(weight.sum())
    return int(total) if total.is_integer() else total


def shown(count: int | float) -> str:
    """A count of shots for people: whole numbers in full, others to 6 digits."""
    return str(count) if isinstance(count, int) else f"{count:.6g}"


def check_shots(speed: np.ndarray, perforated: np.ndarray, weight: np.ndarray, label: str) -> None:
    """Refuse shots no fit can take: too few, one outcome, or outcomes separated by a speed
    (the likelihood then has no maximum). Shots are counted as rounds: a row of weight w
    is w shots."""
    used = weight > 0
    count, go = rounds(weight[used]), rounds(weight[used & perforated])
    no_go = rounds(weight[used & ~perforated])
    rows, go_rows = int(used.sum()), int((used & perforated).sum())
    if count < MIN_SHOTS or go_rows == 0 or go_rows == rows:
        in_rows = f" (in {rows} rows)" if rows != count else ""
        raise V50Error(
            f"{label}: too few shots for a V50 fit: {shown(count)} shots{in_rows}, "
            f"{shown(go)} perforations and {shown(no_go)} non-perforations; a fit needs at "
            f"least {MIN_SHOTS} shots with both outcomes"
        )
    go_speeds, no_go_speeds = speed[used & perforated], speed[used & ~perforated]
    highest_no_go, lowest_go = float(no_go_speeds.max()), float(go_speeds.min())
    if highest_no_go <= lowest_go:
        raise V50Error(
            f"{label}: no zone of mixed results: every perforation (the slowest at "
            f"{lowest_go:.6g} m/s) is at least as fast as every non-perforation (the fastest "
            f"at {highest_no_go:.6g} m/s), so the likelihood has no maximum (sigma -> 0); fire "
            f"more shots between {highest_no_go:.6g} and {lowest_go:.6g} m/s, or use the "
            "MIL-STD-662F estimate (--method mil-std-662f)"
        )
    highest_go, lowest_no_go = float(go_speeds.max()), float(no_go_speeds.min())
    if highest_go <= lowest_no_go:
        raise V50Error(
            f"{label}: perforation does not become more likely with speed in these shots: "
            f"every perforation (the fastest at {highest_go:.6g} m/s) is at most as fast as "
            f"every non-perforation (the slowest at {lowest_no_go:.6g} m/s): they show no "
            "ballistic limit"
        )


def prepared(speed: np.ndarray, perforated: np.ndarray, weight: np.ndarray) -> GoNoGo:
    """The shots of positive weight, centred and scaled by their weighted mean and
    standard deviation (so that the fit's numbers are of order one)."""
    used = weight > 0
    v, w = speed[used], weight[used]
    centre = float(np.average(v, weights=w))
    spread = float(np.sqrt(np.average((v - centre) ** 2, weights=w)))
    sign = np.where(perforated[used], 1.0, -1.0)
    return GoNoGo((v - centre) / spread, sign, w, centre, spread)


def increasing(best: LikelihoodMaximum, label: str) -> LikelihoodMaximum:
    """``best``, refused unless perforation becomes more likely with speed."""
    if best.slope <= 0.0:
        raise V50Error(
            f"{label}: perforation does not become more likely with speed in these shots "
            f"(fitted slope {best.slope:.3g} <= 0): they show no ballistic limit"
        )
    return best
