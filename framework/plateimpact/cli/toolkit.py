"""What a plug-in package uses to provide a command's options and work
(``pi.command_line``): the writer, the one-line usage error, the body and model options,
the output files that land together, and the figure and text helpers every built-in
command uses.

A plug-in package registers such a command as a procedure (``registry.add_procedure``:
an object with ``arguments(parser, registry)`` and ``run(args, registry, out) -> int``),
and the core's command of that name hands it the parser and the arguments
(``plateimpact calibrate``: the ``calibrate`` procedure). Its module then imports these
names from here, never from the command line's own modules.
"""

from __future__ import annotations

import importlib
from typing import TYPE_CHECKING, Any

from ..provenance.metadata import versions
from ..run.progress import reporting_scenes
from ..storage.plate_file import plate_file_text
from ..storage.together import write_together
from .common import (
    UsageError,
    add_dpi_option,
    check_directory,
    figure_output,
    text_output,
    write_atomically,
)
from .formatting import ANGLE, user
from .options import add_body_options, add_model_options, bodies, model_choice, typed
from .writer import Writer

if TYPE_CHECKING:
    from ..figures.calibration_fit import plot_calibration
    from ..figures.style import figure

#: Figure helpers, imported on first use (matplotlib): ``figure`` (a figure in the
#: project's style) and ``plot_calibration`` (shots, DRI curve and model curves).
_FIGURES = {"figure": "..figures.style", "plot_calibration": "..figures.calibration_fit"}

__all__ = [
    "ANGLE",
    "figure",
    "plot_calibration",
    "UsageError",
    "Writer",
    "add_body_options",
    "add_dpi_option",
    "add_model_options",
    "bodies",
    "check_directory",
    "figure_output",
    "model_choice",
    "plate_file_text",
    "reporting_scenes",
    "text_output",
    "typed",
    "user",
    "versions",
    "write_atomically",
    "write_together",
]


def __getattr__(name: str) -> Any:
    if name not in _FIGURES:
        raise AttributeError(f"module {__name__!r} has no attribute {name!r}")
    return getattr(importlib.import_module(_FIGURES[name], __package__), name)
