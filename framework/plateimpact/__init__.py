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
    "Sphere": "bodies",
    "Plate": "bodies",
    "Scene": "scene",
    "SceneBatch": "batch",
    "Parameter": "base.parameters",
    "Range": "base.parameters",
    # plug-in interfaces
    "ResistanceLaw": "resistance",
    "BoundResistance": "resistance",
    "contact_force": "resistance",
    "FailureModel": "failure",
    "Integrator": "integrator",
    "Step": "integrator",
    "StepControl": "integrator",
    "StepperState": "integrator",
    "MAX_STEPS": "integrator",
    "MAX_SECONDS": "integrator",
    "RTOL": "integrator",
    "Column": "plugin",
    "Dynamics": "dynamics",
    "DenseOutput": "dense",
    "PolynomialDenseOutput": "dense",
    "hermite": "dense",
    "BoundBatch": "binding",
    "hookimpl": "hookspecs",
    "PluginRegistry": "registry",
    "default_registry": "registry",
    "load_registry": "registry",
    "BrokenPackage": "discovery",
    # the model and its events
    "ImpactModel": "model",
    "KINEMATIC_STATE": "model",
    "PENETRATION": "model",
    "LATERAL": "model",
    "OBLIQUITY": "model",
    "SPEED": "model",
    "ONSET": "model",
    "CONTACT_LOST": "model",
    "PERFORATED": "model",
    "AT_REST": "model",
    "TURNED_BACK": "model",
    "EVENT_NAMES": "model",
    "EVENT_OUTCOMES": "model",
    "contact_geometry": "geometry",
    "contact_lost_margin": "geometry",
    "force_inclination": "geometry",
    # running
    "Simulation": "simulation",
    "run": "simulation",
    "Variant": "variant",
    "Outcome": "results",
    "Result": "results",
    "BatchResult": "results",
    "Trajectory": "results",
    "CraterSection": "results",
    "Ragged": "ragged",
    # storage
    "Archive": "storage.archive",
    "load_plate_file": "storage.plate_file",
    "save_plate_file": "storage.plate_file",
    "Shots": "storage.shots",
    "synthetic_shots": "storage.synthetic_shots",
    "synthetic_oblique_shots": "storage.synthetic_shots",
    # analysis
    "Study": "study",
    "StudyResults": "study",
    "Comparison": "comparison",
    "Calibration": "calibration",
    "CalibrationReport": "calibration",
    "DriFit": "calibration",
    "calibrate": "calibration",
    "direct_fit": "calibration",
    "energy_balance_start": "calibration",
    "fit_dri": "calibration",
    "newton_fit": "calibration",
    "ProbabilityModel": "calibration",
    "PstarFit": "calibration",
    "PstarTableFit": "calibration",
    "fit_pstar": "calibration",
    "fit_pstar_by_obliquity": "calibration",
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
    "ConvergenceError": "base.errors",
    "V50Error": "base.errors",
    "PluginError": "base.errors",
    "PlateImpactWarning": "base.errors",
    "ArchiveWaitWarning": "base.errors",
    "PluginLoadWarning": "base.errors",
    # files from someone else (a plug-in that reads a file a user names checks it first)
    "check_input": "base.untrusted",
    "load_json": "base.untrusted",
    "printable": "base.untrusted",
}
#: Submodules users reach as attributes (``pi.units.mm``) -> where each is.
_SUBMODULES: dict[str, str] = {
    "batch": "batch",
    "calibration": "calibration",
    "experiment": "experiment",
    "geometry": "geometry",
    "limits": "limits",
    "presets": "presets",
    "units": "units",
    "v50": "v50",
}

__all__ = sorted([*_EXPORTS, *_SUBMODULES, "__version__"])


def __getattr__(name: str) -> Any:
    if name in _EXPORTS:
        value = getattr(importlib.import_module(f".{_EXPORTS[name]}", __name__), name)
    elif name in _SUBMODULES:
        value = importlib.import_module(f".{_SUBMODULES[name]}", __name__)
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
    from . import batch, calibration, experiment, geometry, presets, units, v50
    from .base.errors import (
        ArchiveError,
        ArchiveWaitWarning,
        CalibrationError,
        ConvergenceError,
        IntegrationError,
        ParameterError,
        PlateFileError,
        PlateImpactError,
        PlateImpactWarning,
        PluginError,
        PluginLoadWarning,
        ShotDataError,
        UnknownNameError,
        V50Error,
    )
    from .base.parameters import Parameter, Range
    from .base.untrusted import check_input, load_json, printable
    from .binding import BoundBatch
    from .bodies import Plate, Sphere
    from .calibration import (
        Calibration,
        CalibrationReport,
        DriFit,
        ProbabilityModel,
        PstarFit,
        PstarTableFit,
        calibrate,
        direct_fit,
        energy_balance_start,
        fit_dri,
        fit_pstar,
        fit_pstar_by_obliquity,
        newton_fit,
    )
    from .comparison import Comparison
    from .dense import DenseOutput, PolynomialDenseOutput, hermite
    from .discovery import BrokenPackage
    from .dynamics import Dynamics
    from .experiment import ValidationReport, validate
    from .failure import FailureModel
    from .geometry import contact_geometry, contact_lost_margin, force_inclination
    from .hookspecs import hookimpl
    from .integrator import (
        MAX_SECONDS,
        MAX_STEPS,
        RTOL,
        Integrator,
        Step,
        StepControl,
        StepperState,
    )
    from .model import (
        AT_REST,
        CONTACT_LOST,
        EVENT_NAMES,
        EVENT_OUTCOMES,
        KINEMATIC_STATE,
        LATERAL,
        OBLIQUITY,
        ONSET,
        PENETRATION,
        PERFORATED,
        SPEED,
        TURNED_BACK,
        ImpactModel,
    )
    from .plugin import Column
    from .ragged import Ragged
    from .registry import PluginRegistry, default_registry, load_registry
    from .resistance import BoundResistance, ResistanceLaw, contact_force
    from .results import BatchResult, CraterSection, Outcome, Result, Trajectory
    from .scene import Scene
    from .simulation import Simulation, run
    from .storage.archive import Archive
    from .storage.plate_file import load_plate_file, save_plate_file
    from .storage.shots import Shots
    from .storage.synthetic_shots import synthetic_oblique_shots, synthetic_shots
    from .study import Study, StudyResults
    from .v50 import MilStd662F, V50Fit, fit_v50, mil_std_662f
    from .variant import Variant

    __version__: str
