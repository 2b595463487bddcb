"""The probability of a shot's outcome and residual speed under the model, for fitting P*
and α* (docs/calibration.md, "P* and α* from oblique shots").

A shot fired at measured impact speed v really struck at u = v + ε, ε ~ N(0, s²): s, the
speed scatter [m/s], lumps the error of the speed measurement and the shot-to-shot
scatter of the plate. The model's outcome is a function of u, so the probability that
the shot shows outcome class C is the normal mass that the bands of C hold:

    P(C | v) = Σ over bands [e_j, e_j+1) with outcome in C of Φ((e_j+1 − v)/s) − Φ((e_j − v)/s)

with the bands of the model's line at the shot's obliquity located by
:func:`plateimpact.limits.locate` (the first and last bands reach ±∞). A small blunder
probability keeps every shot's probability above a floor (a mislabelled shot costs a
bounded amount). A perforation whose residual speed Vr was recorded adds a Gaussian
term: Vr ~ N(E[g(u) | u perforates], σ_r² + Var[g(u) | u perforates]), g the model's
residual speed, the conditional moments taken over u above the ballistic limit.
"""

from __future__ import annotations

import math
from collections.abc import Sequence

import attrs
import numpy as np
from scipy.optimize import minimize_scalar
from scipy.special import ndtr, ndtri

from ..base.errors import ParameterError
from ..model.results import Outcome
from ..model.scene import IMPACT_SPEED

#: The speed scatter s [m/s] unless given: about 2-3 % of the report's ballistic limits.
SPEED_SIGMA = 10.0
#: Probability that a shot's recorded outcome is unrelated to its speed (a blunder).
OUTCOME_BLUNDER = 1e-6
#: Each line reaches this many s beyond its slowest and fastest shot.
SPEED_MARGIN = 8.0
#: Quantile nodes of the conditional impact speed for the residual-speed moments.
RESIDUAL_NODES = 64
#: σ_r [m/s] is fitted within these bounds (when not given).
RESIDUAL_SIGMA_BOUNDS = (0.1, 1e3)
#: A shot more than this many s below the ballistic limit takes its residual-speed nodes
#: as if it were this far (keeps P(u perforates) > 0; such a shot is a blunder anyway).
_TAIL = 30.0
#: The recorded-outcome questions a fit may ask of a shot.
QUESTIONS = ("outcome", "ricochet", "perforation")
_ALL = (1 << Outcome.RICOCHET) | (1 << Outcome.EMBEDMENT) | (1 << Outcome.PERFORATION)


@attrs.frozen
class ProbabilityModel:
    """Speed scatter ``speed_sigma`` s [m/s] (> 0) and residual-speed scatter
    ``residual_sigma`` σ_r [m/s] (None: fitted)."""

    speed_sigma: float = SPEED_SIGMA
    residual_sigma: float | None = None

    def __attrs_post_init__(self) -> None:
        given = (("speed_sigma", self.speed_sigma), ("residual_sigma", self.residual_sigma))
        for name, value in given:
            if value is not None and not (math.isfinite(value) and 0.0 < value <= 1e3):
                raise ParameterError(name, f"{name} must be in (0, 1000] m/s, got {value:g}")


@attrs.frozen(eq=False)
class ShotLines:
    """Shots of one likelihood, each on a line (an obliquity and a sphere).

    Per shot: ``speed`` [m/s], ``line`` (index), ``allowed`` (bit 1 << outcome set for
    each outcome the record allows), ``residual`` [m/s] (NaN: no residual-speed term),
    ``weight``. Per line: ``obliquity`` [rad], ``radius`` [m], ``mass`` [kg] and the
    speed range ``start``, ``end`` [m/s].
    """

    speed: np.ndarray
    line: np.ndarray
    allowed: np.ndarray
    residual: np.ndarray
    weight: np.ndarray
    obliquity: np.ndarray
    radius: np.ndarray
    mass: np.ndarray
    start: np.ndarray
    end: np.ndarray
    #: The shots of each line (indices, in order): one sort, so that a likelihood costs
    #: the shots plus the lines, not their product.
    members: tuple[np.ndarray, ...] = attrs.field(
        default=attrs.Factory(lambda self: _members(self.line, self.lines), takes_self=True)
    )

    @property
    def lines(self) -> int:
        return int(self.obliquity.size)


def _members(line: np.ndarray, lines: int) -> tuple[np.ndarray, ...]:
    order = np.argsort(line, kind="stable")
    bounds = np.searchsorted(line[order], np.arange(lines + 1))
    return tuple(order[bounds[k] : bounds[k + 1]] for k in range(lines))


def _bits(*outcomes: Outcome) -> int:
    return sum(1 << int(o) for o in outcomes)


def allowed_outcomes(outcome: np.ndarray, perforated: np.ndarray, question: str) -> np.ndarray:
    """The outcome bits each shot's record allows, for ``question``: ``outcome`` (the
    recorded outcome, else perforated or not), ``ricochet`` (ricochet or not; 0 where the
    record cannot tell) or ``perforation`` (perforated or not)."""
    perforation, other = _bits(Outcome.PERFORATION), _bits(Outcome.RICOCHET, Outcome.EMBEDMENT)
    go_no_go = np.where(perforated, perforation, other)
    if question == "perforation":
        return go_no_go
    known = 1 << outcome.astype(np.int64)
    if question == "outcome":
        return np.where(outcome > 0, known, go_no_go)
    ricochet = np.where(outcome == Outcome.RICOCHET, _bits(Outcome.RICOCHET), _ALL - 2)
    return np.where(outcome > 0, ricochet, np.where(perforated, _ALL - 2, 0))


def shot_lines(
    speed: np.ndarray,
    obliquity: np.ndarray,
    radius: np.ndarray,
    mass: np.ndarray,
    allowed: np.ndarray,
    residual: np.ndarray,
    weight: np.ndarray,
    speed_sigma: float,
) -> ShotLines:
    """Shots grouped onto lines: one per distinct (obliquity [rad], radius [m], mass [kg]),
    each spanning its shots' ``speed`` [m/s] and SPEED_MARGIN × s beyond (s = speed_sigma
    [m/s]; within the model's speed range)."""
    keys = np.column_stack([obliquity, radius, mass])
    unique, line = np.unique(keys, axis=0, return_inverse=True)
    line = line.reshape(-1)
    margin = SPEED_MARGIN * speed_sigma
    low, high = np.full(len(unique), np.inf), np.full(len(unique), -np.inf)
    np.minimum.at(low, line, speed)
    np.maximum.at(high, line, speed)
    low, high = low - margin, high + margin
    bounds = IMPACT_SPEED.range
    return ShotLines(
        speed, line, allowed, residual, weight, unique[:, 0], unique[:, 1], unique[:, 2],
        np.maximum(low, bounds.low), np.minimum(high, bounds.high),
    )  # fmt: skip


@attrs.frozen(eq=False)
class Bands:
    """The model's outcomes along one line: band ``edges`` [m/s] (−∞ first, +∞ last:
    the outcome beyond the line's ends is taken to continue), the ``outcomes`` of the
    bands (neighbours differ), and the residual speeds (``residual`` [m/s]) of the
    scenes run at ``speeds`` [m/s] (sorted) in the line's last run of perforation, which
    starts at ``ballistic_limit`` [m/s] (NaN if the line does not end in perforation,
    −∞ if it perforates throughout)."""

    edges: np.ndarray
    outcomes: np.ndarray
    speeds: np.ndarray
    residual: np.ndarray
    ballistic_limit: float

    @property
    def ricochet_limit(self) -> float:
        """The end of the last ricochet band [m/s]; NaN if there is none or it runs to
        the line's end."""
        found = np.flatnonzero(self.outcomes == Outcome.RICOCHET)
        end = float(self.edges[found[-1] + 1]) if found.size else math.nan
        return end if math.isfinite(end) else math.nan


def log_likelihood(
    shots: ShotLines, bands: Sequence[Bands], model: ProbabilityModel
) -> tuple[float, float]:
    """The log-likelihood of ``shots`` given the model's ``bands`` on each of their lines,
    and the σ_r [m/s] it used (fitted when the model does not give it; NaN: no residual
    speeds)."""
    s = model.speed_sigma
    probability = np.empty(shots.speed.size)
    for on, line in zip(shots.members, bands, strict=True):
        # the normal mass of each band about each shot's speed; ndtr(±inf) is 1 and 0
        cdf = ndtr((line.edges[None, :] - shots.speed[on, None]) / s)
        permitted = (shots.allowed[on, None] >> line.outcomes[None, :].astype(np.int64)) & 1
        probability[on] = (np.diff(cdf, axis=1) * permitted).sum(axis=1)
    choices = sum((shots.allowed >> int(o)) & 1 for o in Outcome)
    blended = (1.0 - OUTCOME_BLUNDER) * probability + OUTCOME_BLUNDER * choices / len(Outcome)
    outcome_term = float(np.sum(shots.weight * np.log(blended)))
    used = np.isfinite(shots.residual)
    if not used.any():
        return outcome_term, math.nan
    mean, variance = _residual_moments(shots, bands, s, used)
    misfit, weight = shots.residual[used] - mean, shots.weight[used]

    def residual_term(sigma: float) -> float:
        total = sigma**2 + variance
        return float(-0.5 * np.sum(weight * (np.log(2 * np.pi * total) + misfit**2 / total)))

    sigma = model.residual_sigma
    if sigma is None:
        low, high = np.log(RESIDUAL_SIGMA_BOUNDS)
        best = minimize_scalar(
            lambda x: -residual_term(math.exp(x)), bounds=(low, high), method="bounded",
            options={"xatol": 1e-6},
        )  # fmt: skip
        sigma = math.exp(float(best.x))
    return outcome_term + residual_term(sigma), sigma


def _residual_moments(
    shots: ShotLines, bands: Sequence[Bands], s: float, used: np.ndarray
) -> tuple[np.ndarray, np.ndarray]:
    """Mean and variance [m/s, (m/s)²] of the model's residual speed g(u) over the
    impact speeds u = v + ε that perforate (u above the ballistic limit), at the
    RESIDUAL_NODES midpoint quantiles of that truncated normal; g² is interpolated
    linearly in u between the line's samples (it is nearly linear: eq 40). Zero where
    the line does not end in perforation."""
    mean = np.zeros(int(used.sum()))
    variance = np.zeros_like(mean)
    levels = (RESIDUAL_NODES - np.arange(RESIDUAL_NODES) - 0.5) / RESIDUAL_NODES
    position = np.cumsum(used) - 1  # each used shot's place among the used
    for members, line in zip(shots.members, bands, strict=True):
        mine = members[used[members]]
        if not mine.size or math.isnan(line.ballistic_limit):
            continue
        on = position[mine]
        v = shots.speed[mine]
        tail = ndtr(np.maximum((v - line.ballistic_limit) / s, -_TAIL))  # P(u perforates)
        u = v[:, None] - s * ndtri(tail[:, None] * levels[None, :])
        g2 = np.interp(u, line.speeds, line.residual**2)
        g = np.sqrt(g2)
        mean[on] = g.mean(axis=1)
        variance[on] = np.maximum(g2.mean(axis=1) - mean[on] ** 2, 0.0)
    return mean, variance
