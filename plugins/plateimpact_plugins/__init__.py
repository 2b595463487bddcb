"""The built-in plug-ins of plateimpact.

This package uses only plateimpact's public API and registers through the
``plateimpact`` entry-point group, exactly as a third-party plug-in package does. The
report's vocabulary that other plug-ins share (plate constants, the failure plane, the
variable-P* table) is the public module :mod:`plateimpact_plugins.report`; the names
re-exported here from it stay for the plug-ins written before it.
"""

from __future__ import annotations

from types import ModuleType

from plateimpact import PluginRegistry, hookimpl

from .dopri5 import DormandPrince54
from .embedded_rk import EmbeddedRungeKutta
from .hinge import Hinge
from .intact import Intact
from .plugging import Plugging
from .poncelet import Poncelet
from .report import CRITICAL_PENETRATION, DENSITY_B, FAILURE_ANGLE, STRENGTH_A
from .report.presets import register_presets
from .report.pstar_table import SAE1010_TABLE, PstarTable
from .scipy_ivp import ScipyIVP
from .segment import Segment
from .separation import PlaneSeparation
from .variable_pstar import VariablePstar

__all__ = [
    "CRITICAL_PENETRATION",
    "DENSITY_B",
    "FAILURE_ANGLE",
    "SAE1010_TABLE",
    "STRENGTH_A",
    "DormandPrince54",
    "EmbeddedRungeKutta",
    "Hinge",
    "Intact",
    "PlaneSeparation",
    "Plugging",
    "Poncelet",
    "PstarTable",
    "ScipyIVP",
    "Segment",
    "VariablePstar",
    "plateimpact_register",
]


@hookimpl
def plateimpact_register(registry: PluginRegistry) -> None:
    """Register the built-in resistance law, failure models and integrators, the
    report's model as the default of each kind, and Table 1's plates and sphere."""
    for cls in (Poncelet, Plugging, DormandPrince54):  # the report's model
        registry.add(cls, default=True)
    for other in (Hinge, VariablePstar, Intact, Segment, ScipyIVP):
        registry.add(other)
    register_presets(registry)
    registry.add_procedure("calibration", _calibration)
    registry.add_procedure("calibrate", _calibrate_command)


def _calibration() -> ModuleType:
    """The report's calibration procedure (imported when a calibration runs: scipy)."""
    from .report import fits  # noqa: PLC0415

    return fits


def _calibrate_command() -> ModuleType:
    """The report's ``plateimpact calibrate``: its options and work (imported when the
    command is invoked)."""
    from .report import calibrate_command  # noqa: PLC0415

    return calibrate_command
