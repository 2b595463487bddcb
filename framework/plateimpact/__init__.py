"""plateimpact: oblique impact of rigid spheres on plates (after NWC TP 5844).

The public API, for study scripts and plug-in authors. SI units throughout; see
:mod:`plateimpact.units` for mm, g and degrees.

Every name is imported on first use (PEP 562), so ``import plateimpact`` is cheap and a
script pays only for what it uses (scipy, h5py and matplotlib are loaded by the parts
that need them).
"""

from __future__ import annotations

import importlib
from typing import TYPE_CHECKING, Any

#: Public name -> the module that defines it.
_EXPORTS: dict[str, str] = {
    # the model's data
    "Sphere": "model.bodies",
    "Plate": "model.bodies",
    "Scene": "model.scene",
    "SceneBatch": "model.batch",
    "Parameter": "base.parameters",
    "Range": "base.parameters",
    # plug-in interfaces
    "ResistanceLaw": "model.resistance",
    "BoundResistance": "model.resistance",
    "contact_force": "model.resistance",
    "FailureModel": "model.failure",
    "Contact": "model.failure",
    "FailureKernels": "model.kernels",
    "KernelContact": "model.kernels",
    "Event": "model.events",
    "EVENTS": "model.events",
    "FAILURE_EVENTS": "model.events",
    "FAILURE_ONSET": "model.events",
    "LOSS_OF_CONTACT": "model.events",
    "PERFORATION": "model.events",
    "REST": "model.events",
    "TURN_BACK": "model.events",
    "Integrator": "solve.integrator",
    "PairTableau": "solve.integrator",
    "Step": "solve.integrator",
    "StepControl": "solve.integrator",
    "StepperState": "solve.integrator",
    "MAX_STEPS": "solve.integrator",
    "MAX_SECONDS": "solve.integrator",
    "RTOL": "solve.integrator",
    "Column": "model.plugin",
    "Plugin": "model.plugin",
    "Dynamics": "solve.dynamics",
    "DenseOutput": "solve.dense",
    "PolynomialDenseOutput": "solve.dense",
    "hermite": "solve.dense",
    "BoundBatch": "model.binding",
    "hookimpl": "registry.hookspecs",
    "PluginRegistry": "registry.plugin_registry",
    "default_registry": "registry.plugin_registry",
    "load_registry": "registry.plugin_registry",
    "BrokenPackage": "registry.discovery",
    # the model and its events
    "ImpactModel": "model.impact",
    "KINEMATIC_STATE": "model.impact",
    "PENETRATION": "model.impact",
    "LATERAL": "model.impact",
    "OBLIQUITY": "model.impact",
    "SPEED": "model.impact",
    "ONSET": "model.events",
    "CONTACT_LOST": "model.events",
    "PERFORATED": "model.events",
    "AT_REST": "model.events",
    "TURNED_BACK": "model.events",
    "EVENT_NAMES": "model.events",
    "EVENT_OUTCOMES": "model.events",
    "contact_geometry": "model.geometry",
    "contact_lost_margin": "model.geometry",
    "force_inclination": "model.geometry",
    # running
    "Simulation": "run.simulation",
    "run": "run.simulation",
    "Variant": "run.variant",
    "Outcome": "model.results",
    "Result": "model.results",
    "BatchResult": "model.results",
    "Trajectory": "model.results",
    "CraterSection": "model.results",
    "Ragged": "model.ragged",
    # storage
    "Archive": "storage.archive",
    "load_plate_file": "storage.plate_file",
    "save_plate_file": "storage.plate_file",
    "Shots": "storage.shots",
    # analysis
    "synthetic_shots": "experiment.synthetic_shots",
    "synthetic_oblique_shots": "experiment.synthetic_shots",
    "Study": "study",
    "StudyResults": "study",
    "Comparison": "comparison",
    "DriFit": "calibration",
    "fit_dri": "calibration",
    "ProbabilityModel": "calibration",
    "validate": "experiment",
    "ValidationReport": "experiment",
    "V50Fit": "v50",
    "MilStd662F": "v50",
    "fit_v50": "v50",
    "mil_std_662f": "v50",
    # errors
    "PlateImpactError": "base.errors",
    "ParameterError": "base.errors",
    "UnknownNameError": "base.errors",
    "IntegrationError": "base.errors",
    "ArchiveError": "base.errors",
    "ShotDataError": "base.errors",
    "PlateFileError": "base.errors",
    "CalibrationError": "base.errors",
    "WorkBoundError": "base.errors",
    "ConvergenceError": "base.errors",
    "V50Error": "base.errors",
    "PluginError": "base.errors",
    "MissingExtraError": "base.errors",
    "PlateImpactWarning": "base.errors",
    "ArchiveWaitWarning": "base.errors",
    "PluginLoadWarning": "base.errors",
    "CompiledPathWarning": "base.errors",
    # files from someone else (a plug-in that reads a file a user names checks it first)
    "check_input": "base.untrusted",
    "load_json": "base.untrusted",
    "printable": "base.untrusted",
}
#: Submodules users reach as attributes (``pi.units.mm``) -> where each is.
_SUBMODULES: dict[str, str] = {
    "batch": "model.batch",
    "calibration": "calibration",
    "command_line": "cli.toolkit",
    "display": "base.display",
    "elementary": "model.elementary",
    "experiment": "experiment",
    "geometry": "model.geometry",
    "kernels": "model.kernels",
    "limits": "limits",
    "presets": "registry.presets",
    "units": "units",
    "v50": "v50",
}

#: Names the report's calibration provided here until it moved to the plug-in package
#: that registers it as the ``calibration`` procedure (issue 22): still found, through
#: the registry, with a DeprecationWarning naming their new module, for one release.
_PROCEDURE_NAMES: dict[str, str] = dict.fromkeys(
    (
        "Calibration",
        "CalibrationReport",
        "calibrate",
        "direct_fit",
        "energy_balance_start",
        "newton_fit",
        "PstarFit",
        "PstarTableFit",
        "fit_pstar",
        "fit_pstar_by_obliquity",
    ),
    "calibration",
)

__all__ = sorted([*_EXPORTS, *_SUBMODULES, "__version__"])


def __getattr__(name: str) -> Any:
    if name in _EXPORTS:
        value = getattr(importlib.import_module(f".{_EXPORTS[name]}", __name__), name)
    elif name in _SUBMODULES:
        value = importlib.import_module(f".{_SUBMODULES[name]}", __name__)
    elif name in _PROCEDURE_NAMES:
        import warnings  # noqa: PLC0415

        from .registry.plugin_registry import default_registry  # noqa: PLC0415

        procedure = default_registry().procedure(_PROCEDURE_NAMES[name])
        warnings.warn(
            f"plateimpact.{name} is deprecated: import it from {procedure.__name__}",
            DeprecationWarning,
            stacklevel=2,
        )
        return getattr(procedure, name)  # not cached: each use warns
    elif name == "__version__":
        from importlib.metadata import PackageNotFoundError, version  # noqa: PLC0415

        try:
            value = version("plateimpact")
        except PackageNotFoundError:  # running from a source tree
            value = "0+unknown"
    else:
        raise AttributeError(f"module 'plateimpact' has no attribute {name!r}")
    globals()[name] = value  # the next look-up is a plain attribute
    return value


def __dir__() -> list[str]:
    return __all__


if TYPE_CHECKING:  # what type checkers and IDEs see
    from . import calibration, experiment, units, v50
    from .base import display
    from .base.errors import (
        ArchiveError,
        ArchiveWaitWarning,
        CalibrationError,
        CompiledPathWarning,
        ConvergenceError,
        IntegrationError,
        MissingExtraError,
        ParameterError,
        PlateFileError,
        PlateImpactError,
        PlateImpactWarning,
        PluginError,
        PluginLoadWarning,
        ShotDataError,
        UnknownNameError,
        V50Error,
        WorkBoundError,
    )
    from .base.parameters import Parameter, Range
    from .base.untrusted import check_input, load_json, printable
    from .calibration import DriFit, ProbabilityModel, fit_dri
    from .cli import toolkit as command_line
    from .comparison import Comparison
    from .experiment import ValidationReport, validate
    from .experiment.synthetic_shots import synthetic_oblique_shots, synthetic_shots
    from .model import batch, elementary, geometry, kernels
    from .model.binding import BoundBatch
    from .model.bodies import Plate, Sphere
    from .model.events import (
        AT_REST,
        CONTACT_LOST,
        EVENT_NAMES,
        EVENT_OUTCOMES,
        EVENTS,
        FAILURE_EVENTS,
        FAILURE_ONSET,
        LOSS_OF_CONTACT,
        ONSET,
        PERFORATED,
        PERFORATION,
        REST,
        TURN_BACK,
        TURNED_BACK,
        Event,
    )
    from .model.failure import Contact, FailureModel
    from .model.geometry import contact_geometry, contact_lost_margin, force_inclination
    from .model.impact import (
        KINEMATIC_STATE,
        LATERAL,
        OBLIQUITY,
        PENETRATION,
        SPEED,
        ImpactModel,
    )
    from .model.kernels import FailureKernels, KernelContact
    from .model.plugin import Column, Plugin
    from .model.ragged import Ragged
    from .model.resistance import BoundResistance, ResistanceLaw, contact_force
    from .model.results import BatchResult, CraterSection, Outcome, Result, Trajectory
    from .model.scene import Scene
    from .registry import presets
    from .registry.discovery import BrokenPackage
    from .registry.hookspecs import hookimpl
    from .registry.plugin_registry import PluginRegistry, default_registry, load_registry
    from .run.simulation import Simulation, run
    from .run.variant import Variant
    from .solve.dense import DenseOutput, PolynomialDenseOutput, hermite
    from .solve.dynamics import Dynamics
    from .solve.integrator import (
        MAX_SECONDS,
        MAX_STEPS,
        RTOL,
        Integrator,
        PairTableau,
        Step,
        StepControl,
        StepperState,
    )
    from .storage.archive import Archive
    from .storage.plate_file import load_plate_file, save_plate_file
    from .storage.shots import Shots
    from .study import Study, StudyResults
    from .v50 import MilStd662F, V50Fit, fit_v50, mil_std_662f

    __version__: str
