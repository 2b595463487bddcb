"""Exceptions raised at the user's edge.

Every error a user can cause by input is a :class:`PlateImpactError`; its message is one
line that names the parameter and the allowed range, so the command line can print it
as it is (exit code 2, no traceback).
"""

from __future__ import annotations


class PlateImpactError(Exception):
    """Base class of the errors caused by input (bad parameters, unknown names)."""


class ParameterError(PlateImpactError, ValueError):
    """A parameter is outside its allowed range.

    Attributes
    ----------
    parameter : str
        The name of the parameter, as the Python API spells it (``impact_obliquity``).
    """

    def __init__(self, parameter: str, message: str) -> None:
        super().__init__(message)
        self.parameter = parameter


class WorkBoundError(ParameterError):
    """A request would run more scenes than its bound, by an estimate made before any
    scene runs. ``parameter`` names what sets the work; the message gives the estimate,
    the bound, and how to lift it (``max_scenes=None``; ``--force`` on the command line)."""


class UnknownNameError(PlateImpactError, LookupError):
    """A plug-in (resistance law, failure model, integrator) or preset name is unknown."""


class IntegrationError(PlateImpactError, RuntimeError):
    """An integrator could not bring every scene of a batch to an outcome."""


class ArchiveError(PlateImpactError, OSError):
    """An archive cannot be written or read: missing directory, not HDF5, a checksum
    mismatch, another process writing it."""


class ShotDataError(PlateImpactError, ValueError):
    """Shot data (impact and residual speeds) cannot be read or fails a check; the
    message names the file, line and column."""


class PlateFileError(PlateImpactError, ValueError):
    """A plate file cannot be read or holds an invalid plate."""


class InputsError(PlateImpactError, ValueError):
    """An inputs record (``run --json``) cannot be read back; the message names the file
    and the key."""


class CalibrationError(PlateImpactError, RuntimeError):
    """No a, b can be found from the shots: too few perforations, a DRI fit outside the
    model's range, or an iteration that did not converge."""


class ConvergenceError(CalibrationError):
    """The report's Newton iteration (eqs 44–49) did not converge within its iterations."""


class V50Error(PlateImpactError, ValueError):
    """No V50 can be estimated from go/no-go shots: too few shots, only one outcome,
    perforations and non-perforations that do not overlap in speed (the likelihood has
    no maximum), or the conditions of MIL-STD-662F not met. The message says what to do."""


class PluginError(PlateImpactError):
    """A plug-in is malformed or two plug-ins conflict: an undeclared or missing prepared
    column, two declarations of one plate constant that disagree, a class that cannot be
    registered. The message names the plug-ins."""


class MissingExtraError(PlateImpactError, ImportError):
    """An optional dependency a feature needs is not installed; the message names the
    feature, the package and the extra that installs it (``pip install
    'plateimpact[review]'``)."""


class PlateImpactWarning(UserWarning):
    """Base class of plateimpact's own warnings: the command line prints each as one line,
    ``plateimpact: warning: ...``."""


class CompiledPathWarning(PlateImpactWarning):
    """The compiled path could not run (numba missing or failing): the numpy path ran."""


class PluginLoadWarning(PlateImpactWarning):
    """An installed plug-in package failed to load and was skipped; the message names
    the distribution, the entry point and the error. Filter it like any warning
    (``warnings.filterwarnings("ignore", category=PluginLoadWarning)``)."""


class ArchiveWaitWarning(PlateImpactWarning):
    """A writer waits for another to finish with an archive, or saved its run aside."""
