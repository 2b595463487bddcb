"""The report's vocabulary (NWC TP 5844), public: what a plug-in shares with the built-ins.

A third-party plug-in imports from here, never from the built-ins' own modules:

* Table 1's plate constants, declared once: :data:`STRENGTH_A` (a [N/m²]) and
  :data:`DENSITY_B` (b [kg/m³]) of eq 1, :data:`CRITICAL_PENETRATION` (P* [m]) and
  :data:`FAILURE_ANGLE` (α* [rad]) of eq 8. A plug-in that reads one declares the same
  object, so that every model means the same thing by ``plate.a``;
* the failure plane of eq 8 (:func:`failure_plane_depth`) and the base of the failure
  models that separate along it (:class:`PlaneSeparation`, eqs 8–15);
* the variable-P* table (:class:`PstarTable`, its file columns :data:`TABLE_COLUMNS`, the
  report's :data:`SAE1010_TABLE`);
* the report's calibration procedure (:mod:`.fits`: :func:`calibrate`, :func:`newton_fit`,
  :func:`direct_fit`, :func:`fit_pstar`, ...), imported on first use (it needs scipy).

The plug-in package registers Table 1's plates and sphere with the registry, so that the
core finds them by name (``--preset``, ``pi.presets``) without knowing them.
"""

from __future__ import annotations

import importlib
from typing import TYPE_CHECKING, Any

from .constants import CRITICAL_PENETRATION, DENSITY_B, FAILURE_ANGLE, STRENGTH_A
from .plane import failure_plane_depth
from .pstar_table import SAE1010_TABLE, TABLE_COLUMNS, PstarTable

#: The calibration procedure's public names (:mod:`.fits`).
CALIBRATION = (
    "Calibration",
    "CalibrationReport",
    "PstarFit",
    "PstarTableFit",
    "calibrate",
    "direct_fit",
    "energy_balance_start",
    "fit_pstar",
    "fit_pstar_by_obliquity",
    "newton_fit",
    "swept_volume",
)

#: Names imported on first use: PlaneSeparation's module imports the constants from here,
#: so this package cannot import it while it loads; the calibration needs scipy.
_LAZY: dict[str, str] = {
    "PlaneSeparation": "plateimpact_plugins.separation",
    **dict.fromkeys(CALIBRATION, "plateimpact_plugins.report.fits"),
}

__all__ = [
    "Calibration",
    "CalibrationReport",
    "PstarFit",
    "PstarTableFit",
    "calibrate",
    "direct_fit",
    "energy_balance_start",
    "fit_pstar",
    "fit_pstar_by_obliquity",
    "newton_fit",
    "swept_volume",
    "CRITICAL_PENETRATION",
    "DENSITY_B",
    "FAILURE_ANGLE",
    "SAE1010_TABLE",
    "STRENGTH_A",
    "TABLE_COLUMNS",
    "PlaneSeparation",
    "PstarTable",
    "failure_plane_depth",
]


def __getattr__(name: str) -> Any:
    if name not in _LAZY:
        raise AttributeError(f"module {__name__!r} has no attribute {name!r}")
    value = getattr(importlib.import_module(_LAZY[name]), name)
    globals()[name] = value
    return value


if TYPE_CHECKING:
    from ..separation import PlaneSeparation
    from .fits import (
        Calibration,
        CalibrationReport,
        PstarFit,
        PstarTableFit,
        calibrate,
        direct_fit,
        energy_balance_start,
        fit_pstar,
        fit_pstar_by_obliquity,
        newton_fit,
        swept_volume,
    )
