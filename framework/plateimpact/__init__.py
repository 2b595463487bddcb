"""plateimpact: oblique impact of rigid spheres on plates (after NWC TP 5844).

The public API, for study scripts and plug-in authors. SI units throughout; see
:mod:`plateimpact.units` for mm, g and degrees.
"""

from __future__ import annotations

from importlib.metadata import PackageNotFoundError, version

from . import geometry, presets, units
from .storage.archive import Archive
from .batch import SceneBatch
from .bodies import Plate, Sphere
from .calibration import (
    Calibration,
    CalibrationReport,
    DriFit,
    calibrate,
    direct_fit,
    energy_balance_start,
    fit_dri,
    newton_fit,
)
from .binding import BoundBatch
from .dense import DenseOutput, PolynomialDenseOutput, hermite
from .dynamics import Dynamics
from .errors import (
    ArchiveError,
    CalibrationError,
    ConvergenceError,
    IntegrationError,
    ParameterError,
    PlateFileError,
    PlateImpactError,
    PluginError,
    ShotDataError,
    UnknownNameError,
)
from .failure import FailureModel
from .geometry import contact_geometry, contact_lost_margin, force_inclination
from .hookspecs import hookimpl
from .integrator import MAX_STEPS, RTOL, Integrator, Step, StepControl, StepperState
from .parameters import Parameter, Range
from .plugin import Column
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
from .storage.plate_file import load_plate_file, save_plate_file
from .registry import PluginRegistry, default_registry, load_registry
from .resistance import BoundResistance, ResistanceLaw, contact_force
from .results import BatchResult, Outcome, Result, Trajectory
from .scene import Scene
from .storage.shots import Shots, synthetic_shots
from .simulation import Simulation, run
from .study import Comparison, Study, StudyResults
from .variant import Variant

try:
    __version__ = version("plateimpact")
except PackageNotFoundError:  # running from a source tree
    __version__ = "0+unknown"

__all__ = [
    "AT_REST",
    "CONTACT_LOST",
    "EVENT_NAMES",
    "EVENT_OUTCOMES",
    "KINEMATIC_STATE",
    "LATERAL",
    "MAX_STEPS",
    "OBLIQUITY",
    "ONSET",
    "PENETRATION",
    "PERFORATED",
    "RTOL",
    "SPEED",
    "TURNED_BACK",
    "Archive",
    "ArchiveError",
    "CalibrationError",
    "CalibrationReport",
    "ConvergenceError",
    "BatchResult",
    "BoundBatch",
    "BoundResistance",
    "Calibration",
    "Column",
    "Comparison",
    "DenseOutput",
    "DriFit",
    "Dynamics",
    "FailureModel",
    "ImpactModel",
    "IntegrationError",
    "Integrator",
    "Outcome",
    "Parameter",
    "ParameterError",
    "Plate",
    "PlateFileError",
    "PlateImpactError",
    "PluginError",
    "PluginRegistry",
    "PolynomialDenseOutput",
    "Range",
    "ResistanceLaw",
    "Result",
    "Scene",
    "SceneBatch",
    "ShotDataError",
    "Shots",
    "Simulation",
    "Step",
    "StepControl",
    "StepperState",
    "Study",
    "StudyResults",
    "Sphere",
    "Trajectory",
    "UnknownNameError",
    "Variant",
    "calibrate",
    "contact_force",
    "contact_geometry",
    "contact_lost_margin",
    "default_registry",
    "direct_fit",
    "energy_balance_start",
    "fit_dri",
    "force_inclination",
    "geometry",
    "hermite",
    "hookimpl",
    "load_plate_file",
    "load_registry",
    "newton_fit",
    "presets",
    "run",
    "save_plate_file",
    "synthetic_shots",
    "units",
]
