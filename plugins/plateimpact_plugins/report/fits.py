"""The report's calibration procedure, registered as the ``calibration`` procedure that
``plateimpact calibrate`` runs (docs/calibration.md):

* a and b from residual speeds at normal incidence: the DRI fit of the shots (eqs 40–41),
  the report's Newton iteration (eqs 44–49) from the energy-balance start (eqs 42–43),
  and a direct least-squares fit (:func:`calibrate`, :func:`newton_fit`,
  :func:`direct_fit`, :func:`energy_balance_start`, :func:`swept_volume`);
* P* (and α*) from oblique shots, a and b held: one P* (:func:`fit_pstar`) or the
  report's variable P* by obliquity (:func:`fit_pstar_by_obliquity`), written as the
  table the ``variable-pstar`` model reads.

Built on the core's tools for fitting any declared plate constants
(:mod:`plateimpact.calibration`), with the report's constants a, b, P*, α* and its
failure plane (eq 8) from this package.
"""

from __future__ import annotations

from .ab_fits import (
    AB_SCENES_PER_SHOT,
    DIFFERENCE_STEP,
    NEWTON_TOLERANCE,
    Calibration,
    CalibrationReport,
    calibrate,
    direct_fit,
    newton_fit,
)
from .ab_start import energy_balance_start, log_domain, model_residual_speeds, swept_volume
from .pstar_fits import (
    MIN_SHOTS,
    PstarFit,
    PstarRow,
    PstarTableFit,
    fit_pstar,
    fit_pstar_by_obliquity,
)
from .pstar_plan import MAX_FIT_SCENES
from .pstar_search import NEAR, PSTAR_RANGE, PSTAR_STEP, SCAN_POINTS, PstarEstimate

__all__ = [
    "AB_SCENES_PER_SHOT",
    "DIFFERENCE_STEP",
    "MAX_FIT_SCENES",
    "MIN_SHOTS",
    "NEAR",
    "NEWTON_TOLERANCE",
    "PSTAR_RANGE",
    "PSTAR_STEP",
    "SCAN_POINTS",
    "Calibration",
    "CalibrationReport",
    "PstarEstimate",
    "PstarFit",
    "PstarRow",
    "PstarTableFit",
    "calibrate",
    "direct_fit",
    "energy_balance_start",
    "fit_pstar",
    "fit_pstar_by_obliquity",
    "log_domain",
    "model_residual_speeds",
    "newton_fit",
    "swept_volume",
]
