"""V50, σ, V10 and V90 from go/no-go shots by maximum likelihood (probit or logit), with
profile-likelihood and parametric-bootstrap confidence intervals (docs/experiment.md,
"V50 statistics").

>>> fit = fit_v50(speeds, perforated, method="probit")
>>> fit.v50_m_s, fit.v50_ci_m_s, fit.sigma_m_s, fit.v90_bootstrap_ci_m_s
"""

from __future__ import annotations

from typing import Any

import attrs
import numpy as np

from ..base.errors import ParameterError
from ..storage.shots import Shots
from . import views
from .bootstrap import bootstrap_intervals
from .likelihood import (
    PROBIT,
    SHOTS,
    check_shots,
    go_no_go,
    increasing,
    link_of,
    prepared,
    rounds,
)
from .profile import Interval, profile_intervals
from .solver import maximum

#: The quantiles reported, by name: the speed at which P(perforation) is p.
LEVELS = {"v50": 0.5, "v10": 0.1, "v90": 0.9}
#: Confidence levels accepted, and bootstrap resamples (0: none).
CONFIDENCE_RANGE = (0.5, 0.999)
DEFAULT_BOOTSTRAP, MAX_BOOTSTRAP = 1000, 100_000


@attrs.frozen(eq=False, repr=False)
class V50Fit:
    """A probit or logit fit of P(perforation) = F((v − V50)/s) to go/no-go shots.

    Speeds in m/s. ``sigma_m_s`` is the standard deviation of the fitted distribution of
    the ballistic limit: s for probit, s π/√3 for logit (whose scale s is
    ``scale_m_s``). V10 and V90 are the speeds of 10 % and 90 % perforation on the
    fitted curve. Each ``*_ci_m_s`` is the profile-likelihood interval [low, high] at
    ``confidence``, each ``*_bootstrap_ci_m_s`` the parametric-bootstrap percentile
    interval of ``bootstrap_resamples`` resamples (None if 0), of which
    ``bootstrap_separated`` had outcomes that did not overlap, ``bootstrap_flat`` no
    rise of perforation with speed, and ``bootstrap_failed`` no fit any solver converged
    on (left out; none is known) (plateimpact.v50.bootstrap). An interval end is
    None where the data do not bound it (for a speed: above 0 m/s). ``mixed_zone_m_s`` is
    [the slowest perforation, the fastest non-perforation]. ``rounds`` (also ``shots``)
    counts the shots with their weights (a row of weight w is w shots), ``perforations``
    the perforating ones; ``rows`` the rows of positive weight. ``fit_v50`` raises
    rather than return a fit that did not converge, so ``converged`` is True on every fit
    it returns.
    """

    method: str
    v50_m_s: float
    sigma_m_s: float
    v10_m_s: float
    v90_m_s: float
    scale_m_s: float
    confidence: float
    v50_ci_m_s: Interval
    sigma_ci_m_s: Interval
    v10_ci_m_s: Interval
    v90_ci_m_s: Interval
    v50_bootstrap_ci_m_s: Interval | None
    sigma_bootstrap_ci_m_s: Interval | None
    v10_bootstrap_ci_m_s: Interval | None
    v90_bootstrap_ci_m_s: Interval | None
    bootstrap_resamples: int
    bootstrap_separated: int
    bootstrap_flat: int
    bootstrap_failed: int
    shots: int | float
    perforations: int | float
    rounds: int | float
    rows: int
    mixed_zone_m_s: tuple[float, float]
    log_likelihood: float
    iterations: int
    converged: bool

    def probability(self, speed: np.ndarray | float) -> np.ndarray:
        """The fitted P(perforation) at ``speed`` [m/s]."""
        z = (np.asarray(speed, dtype=float) - self.v50_m_s) / self.scale_m_s
        return np.asarray(np.exp(link_of(self.method).log_cdf(z)))

    def __repr__(self) -> str:
        return views.fit_repr(self)

    def _repr_html_(self) -> str:
        return views.fit_html(self)

    def to_json(self) -> dict[str, Any]:
        """The fit as JSON values: m/s, intervals as [low, high] lists (null: unbounded)."""
        found = {f.name: getattr(self, f.name) for f in attrs.fields(V50Fit)}
        return {
            key: list(value) if isinstance(value, tuple) else value for key, value in found.items()
        }


def _check_options(confidence: float, bootstrap: int) -> None:
    low, high = CONFIDENCE_RANGE
    if not low <= confidence <= high:  # NaN fails too
        raise ParameterError(
            "confidence", f"confidence must be in [{low:g}, {high:g}], got {confidence!r}"
        )
    if (
        isinstance(bootstrap, bool)
        or not isinstance(bootstrap, int | np.integer)
        or not (0 <= bootstrap <= MAX_BOOTSTRAP)
    ):
        raise ParameterError(
            "bootstrap",
            f"bootstrap must be a whole number of resamples in [0, {MAX_BOOTSTRAP}], "
            f"got {bootstrap!r}",
        )


def fit_v50(
    speed: np.ndarray | Shots,
    perforated: np.ndarray | None = None,
    weight: np.ndarray | None = None,
    *,
    method: str = PROBIT,
    confidence: float = 0.95,
    bootstrap: int = DEFAULT_BOOTSTRAP,
    rng: np.random.Generator | int | None = 0,
    label: str = SHOTS,
) -> V50Fit:
    """Fit P(perforation) = F((v − V50)/s) to go/no-go shots by maximum likelihood.

    ``speed`` [m/s], ``perforated`` (bool) and ``weight`` (frequency weights >= 0,
    default 1) have one value per shot; or ``speed`` is :class:`~plateimpact.Shots`
    (what :meth:`~plateimpact.Shots.from_csv` reads), alone: shots at one obliquity,
    their ``impact_speed``, ``perforated`` and ``weight``, the same fit. ``method`` is
    ``probit`` (F = Φ) or ``logit`` (the logistic CDF). ``confidence`` sets the
    intervals' level; ``bootstrap`` resamples (0: none) are drawn with ``rng`` (a
    Generator, or a seed: the default 0 makes a fit reproducible). ``label`` names the
    shots in error messages (default: Shots' file). The shots are taken in one order (by
    speed, outcome, weight), so the fit and its bootstrap do not depend on the order
    given.

    Raises :class:`~plateimpact.base.errors.V50Error` (one line) for fewer than 4 shots
    (weights counted), only one outcome, outcomes separated by a speed (the likelihood
    has no maximum), or a fit that finds perforation less likely at higher speeds (a
    fit that does not converge would be refused too: none is known);
    :class:`~plateimpact.base.errors.ParameterError` for bad arguments.
    """
    link = link_of(method)
    _check_options(confidence, bootstrap)
    v, y, w, label = go_no_go(speed, perforated, weight, label)
    # One order whatever the file's: the same numbers, bootstrap draws included.
    order = np.lexsort((w, y, v))
    v, y, w = v[order], y[order], w[order]
    check_shots(v, y, w, label)
    shots = prepared(v, y, w)
    best = increasing(maximum(shots, link, label), label)
    intervals = profile_intervals(shots, link, best, confidence, LEVELS)
    point = {name: shots.speed(best.location + best.scale * link.quantile(p))
             for name, p in LEVELS.items()}  # fmt: skip
    scale = shots.spread * best.scale
    resampled = bootstrap_intervals(
        v, y, w, link, (point["v50"], scale), bootstrap, rng, confidence, LEVELS
    )
    used = w > 0
    count = rounds(w[used])
    return V50Fit(
        method=link.name,
        v50_m_s=point["v50"],
        sigma_m_s=scale * link.sigma_per_scale,
        v10_m_s=point["v10"],
        v90_m_s=point["v90"],
        scale_m_s=scale,
        confidence=confidence,
        v50_ci_m_s=intervals["v50"],
        sigma_ci_m_s=intervals["sigma"],
        v10_ci_m_s=intervals["v10"],
        v90_ci_m_s=intervals["v90"],
        v50_bootstrap_ci_m_s=resampled.intervals.get("v50"),
        sigma_bootstrap_ci_m_s=resampled.intervals.get("sigma"),
        v10_bootstrap_ci_m_s=resampled.intervals.get("v10"),
        v90_bootstrap_ci_m_s=resampled.intervals.get("v90"),
        bootstrap_resamples=bootstrap,
        bootstrap_separated=resampled.separated,
        bootstrap_flat=resampled.flat,
        bootstrap_failed=resampled.failed,
        shots=count,
        perforations=rounds(w[used & y]),
        rounds=count,
        rows=int(used.sum()),
        mixed_zone_m_s=(float(v[used & y].min()), float(v[used & ~y].max())),
        log_likelihood=-best.negative_log_likelihood,
        iterations=best.iterations,
        converged=True,
    )


__all__ = ["LEVELS", "V50Fit", "fit_v50"]
