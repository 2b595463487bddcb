"""Calibration of the Poncelet constants a and b from residual speeds at normal incidence.

Three steps, after the report's eqs 40–49 (docs/calibration.md):

* :func:`fit_dri` — the DRI (Recht–Ipson) fit Vr = R (Vs² − V0²)^½ (eq 40) by linear least
  squares of Vr² on Vs² (eq 41, M = R², B = −R² V0²);
* :func:`newton_fit` — the report's iteration: the model is run at normal incidence at the
  shots' impact speeds, its residual speeds fitted the same way, and a, b corrected by 2×2
  Newton steps on the differences in R and V0 (eqs 44–49), from the energy-balance start
  of :func:`energy_balance_start` (our repair of eqs 42–43);
* :func:`direct_fit` — a and b by bounded nonlinear least squares of the model's residual
  speeds to the shots.

P* and α* are fixed beforehand (from craters, as in the report). Every model evaluation
is one batch through :meth:`Simulation.run_batch`.

With a and b known, :func:`fit_pstar` fits P* (and α*) to oblique shots by maximum
likelihood of their outcomes and residual speeds (:class:`ProbabilityModel`), and
:func:`fit_pstar_by_obliquity` the report's variable P*: a ricochet-range and a
perforation-range P* at each obliquity, as the ``variable-pstar`` plug-in's table.
"""

from __future__ import annotations

from .dri import MIN_PERFORATIONS, DriFit, fit_dri
from .fits import (
    DIFFERENCE_STEP,
    NEWTON_TOLERANCE,
    Calibration,
    CalibrationReport,
    calibrate,
    direct_fit,
    newton_fit,
)
from .outcome_model import ProbabilityModel
from .pstar import PstarFit, PstarRow, PstarTableFit, fit_pstar, fit_pstar_by_obliquity
from .start import energy_balance_start, model_residual_speeds, swept_volume

__all__ = [
    "DIFFERENCE_STEP",
    "MIN_PERFORATIONS",
    "NEWTON_TOLERANCE",
    "Calibration",
    "CalibrationReport",
    "DriFit",
    "ProbabilityModel",
    "PstarFit",
    "PstarRow",
    "PstarTableFit",
    "calibrate",
    "direct_fit",
    "energy_balance_start",
    "fit_dri",
    "fit_pstar",
    "fit_pstar_by_obliquity",
    "model_residual_speeds",
    "newton_fit",
    "swept_volume",
]
