"""The report's vocabulary (NWC TP 5844), public: what a plug-in shares with the built-ins.

A third-party plug-in imports from here, never from the built-ins' own modules:

* Table 1's plate constants, declared once: :data:`STRENGTH_A` (a [N/m²]) and
  :data:`DENSITY_B` (b [kg/m³]) of eq 1, :data:`CRITICAL_PENETRATION` (P* [m]) and
  :data:`FAILURE_ANGLE` (α* [rad]) of eq 8. A plug-in that reads one declares the same
  object, so that every model means the same thing by ``plate.a``;
* the failure plane of eq 8 (:func:`failure_plane_depth`) and the base of the failure
  models that separate along it (:class:`PlaneSeparation`, eqs 8–15);
* the variable-P* table (:class:`PstarTable`, its file columns :data:`TABLE_COLUMNS`, the
  report's :data:`SAE1010_TABLE`).

The plug-in package registers Table 1's plates and sphere with the registry, so that the
core finds them by name (``--preset``, ``pi.presets``) without knowing them.
"""

from __future__ import annotations

import importlib
from typing import TYPE_CHECKING, Any

from .constants import CRITICAL_PENETRATION, DENSITY_B, FAILURE_ANGLE, STRENGTH_A
from .plane import failure_plane_depth
from .pstar_table import SAE1010_TABLE, TABLE_COLUMNS, PstarTable

#: Names defined beside this package, imported on first use: PlaneSeparation's module
#: imports the constants from here, so this package cannot import it while it loads.
_LAZY: dict[str, str] = {"PlaneSeparation": "plateimpact_plugins.separation"}

__all__ = [
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
