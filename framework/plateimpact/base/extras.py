"""The optional dependencies, each installed by an extra of pyproject.toml and imported
only where a feature asks for it: without it the feature says, in one line, what to
install (the command line prints that line, exit code 2)."""

from __future__ import annotations

import importlib
from types import ModuleType

from .errors import MissingExtraError

#: xarray and pandas: the labelled tables, ``to_xarray()`` and ``to_dataframe()``.
REVIEW = "plateimpact[review]"
#: SALib: Sobol' sensitivity indices.
SOBOL = "plateimpact[sobol]"
#: numba: the compiled path (without it the numpy path runs, with one warning).
FAST = "plateimpact[fast]"


def optional(module: str, wanted_by: str, extra: str) -> ModuleType:
    """``module`` imported, or MissingExtraError (an ImportError) in one line naming
    what wanted it and the ``extra`` that installs it."""
    try:
        return importlib.import_module(module)
    except ImportError:
        raise MissingExtraError(
            f"{wanted_by} needs {module}, which is not installed: pip install '{extra}'"
        ) from None
