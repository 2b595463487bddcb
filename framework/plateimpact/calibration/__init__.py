"""Fitting declared plate constants to shots: the tools, for any model (docs/calibration.md).

* :func:`fit_dri` — the DRI (Recht–Ipson) fit Vr = R (Vs² − V0²)^½ (eq 40) of residual
  speeds by linear least squares of Vr² on Vs² (eq 41, M = R², B = −R² V0²);
* :func:`model_residual_speeds` — the model's residual speeds at normal incidence for
  candidate values of any declared plate constants, one batch; :func:`normal_shots`, the
  shots such a fit takes; :func:`in_model_domain`, :func:`log_domain`, the ranges the
  model declares for the constants fitted;
* :class:`ProbabilityModel`, :func:`log_likelihood` — the probability of shots' outcomes
  and residual speeds given the model's outcome bands along their lines, and
  :class:`LineModel`, those bands for candidate plate constants (any names), all
  candidates in the same batches.

The report's own procedure — a and b by its Newton iteration (eqs 44–49) and a direct
fit, P* and α* from oblique shots, the variable-P* table — is the plug-in package's: the
built-ins register it as the ``calibration`` procedure (``registry.procedure``), which
``plateimpact calibrate`` runs.
"""

from __future__ import annotations

from .dri import MIN_PERFORATIONS, DriFit, fit_dri
from .model_lines import GROUP_SCENES, MAX_FIT_SCENES, Cost, LineModel, check_finder, scan_scenes
from .outcome_model import (
    OUTCOME_BLUNDER,
    QUESTIONS,
    RESIDUAL_SIGMA_BOUNDS,
    SPEED_SIGMA,
    Bands,
    ProbabilityModel,
    ShotLines,
    allowed_outcomes,
    log_likelihood,
    shot_lines,
)
from .residual_speeds import (
    declared_ranges,
    fit_model_dri,
    in_model_domain,
    log_domain,
    model_residual_speeds,
    normal_shots,
)

__all__ = [
    "GROUP_SCENES",
    "MAX_FIT_SCENES",
    "MIN_PERFORATIONS",
    "OUTCOME_BLUNDER",
    "QUESTIONS",
    "RESIDUAL_SIGMA_BOUNDS",
    "SPEED_SIGMA",
    "Bands",
    "Cost",
    "DriFit",
    "LineModel",
    "ProbabilityModel",
    "ShotLines",
    "allowed_outcomes",
    "check_finder",
    "declared_ranges",
    "fit_dri",
    "fit_model_dri",
    "in_model_domain",
    "log_domain",
    "log_likelihood",
    "model_residual_speeds",
    "normal_shots",
    "scan_scenes",
    "shot_lines",
]
