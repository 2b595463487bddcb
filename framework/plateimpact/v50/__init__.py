"""V50 statistics of go/no-go shots (docs/experiment.md, "V50 statistics").

``fit_v50`` fits P(perforation) against impact speed by maximum likelihood (probit or
logit) with profile-likelihood and bootstrap confidence intervals; ``mil_std_662f`` is
the V50 of MIL-STD-662F, the mean of equal numbers of the highest partial and the lowest
complete penetrations within a stated velocity spread. Both take arrays (speeds [m/s],
perforated, weights), so any reader of shots can feed them.

>>> fit = fit_v50(shots.impact_speed, shots.perforated, shots.weight)
>>> fit.v50_m_s, fit.v50_ci_m_s, fit.sigma_m_s
>>> mil_std_662f(shots.impact_speed, shots.perforated).v50_m_s
"""

from __future__ import annotations

from .fit import LEVELS, V50Fit, fit_v50
from .likelihood import METHODS, MIN_SHOTS
from .mil_std import COUNTS, DEFAULT_SPREAD, MilStd662F, mil_std_662f
from .profile import Interval

__all__ = [
    "COUNTS",
    "DEFAULT_SPREAD",
    "LEVELS",
    "METHODS",
    "MIN_SHOTS",
    "Interval",
    "MilStd662F",
    "V50Fit",
    "fit_v50",
    "mil_std_662f",
]
