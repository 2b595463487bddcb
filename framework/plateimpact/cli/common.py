"""What every command shares: the one-line usage error, the argument parser, output
files written atomically and checked before any work (standard output is the writer's:
:mod:`plateimpact.cli.writer`)."""

from __future__ import annotations

import argparse
import csv
import io
import math
import os
import sys
from collections.abc import Iterable, Sequence
from pathlib import Path
from typing import TYPE_CHECKING, Any, NoReturn

from ..base.errors import PlateImpactError
from ..base.untrusted import printable, spreadsheet_safe
from ..storage.output import (
    FIGURE_DPI,
    FIGURE_DPI_RANGE,
    OutputError,
    check_output,
    check_path,
    shown_path,
    unwritable,
    write_text,
)
from ..storage.together import Output
from .writer import Writer

if TYPE_CHECKING:
    from matplotlib.figure import Figure


class UsageError(PlateImpactError):
    """A command-line argument is malformed."""


class Parser(argparse.ArgumentParser):
    """An argument parser whose errors are one line and exit code 2, without the usage,
    and whose help and version go through the command's writer (``out``)."""

    def __init__(self, *args: Any, out: Writer | None = None, **kwargs: Any) -> None:
        kwargs.setdefault("allow_abbrev", False)  # a mistyped prefix is an error, not a guess
        super().__init__(*args, **kwargs)
        self.out = out or Writer()

    def error(self, message: str) -> NoReturn:
        self.exit(2, f"plateimpact: error: {printable(message)}\n")

    def _print_message(self, message: str, file: Any = None) -> None:
        # --help and --version go through the one writer: argparse's own swallows a
        # failed write (and Python reports it at exit)
        if message and (file is None or file is sys.stdout):
            self.out.write(message)
        else:
            super()._print_message(message, file)


def check_directory(path: str | None, flag: str, kind: str = "csv") -> None:
    """Refuse, before any work is done, an output ``path`` that could not be written
    (storage.output.check_output: missing or unwritable directory, a directory, not a
    regular file, read-only, a figure format matplotlib cannot write)."""
    if path is not None:
        check_output(path, flag, kind)


def output_directory(path: str, flag: str, spare: int = 0) -> Path:
    """The directory ``path``, created if need be (its parent must exist), after refusing
    with one line naming ``flag`` what could not hold the outputs: an empty name, a path
    too long (``spare`` bytes kept for the names of the files inside), a name too long,
    a file where a directory must be, a missing parent, a directory that cannot be
    written (read-only filesystem included). Call it before any work."""
    if not path.strip():
        raise OutputError(f"{flag}: give a directory name, got {path!r}")
    if "\0" in path:
        raise OutputError(f"{flag}: a directory name cannot hold a NUL character")
    real = Path(os.path.realpath(path))
    check_path(real, flag, spare)
    if real.exists():
        if not real.is_dir():
            raise OutputError(f"{flag}: {shown_path(path)} exists and is not a directory")
        where = real
    else:
        where = real.parent
        if not where.is_dir():
            raise OutputError(f"{flag}: directory {shown_path(str(where))} does not exist")
    if not os.access(where, os.W_OK | os.X_OK):
        raise OutputError(f"{flag}: directory {shown_path(str(where))} is {unwritable(where)}")
    try:
        real.mkdir(exist_ok=True)
    except OSError as exc:
        reason = exc.strerror or type(exc).__name__
        raise OutputError(f"{flag}: cannot create {shown_path(path)}: {reason}") from None
    return real


def dots_per_inch(text: str) -> float:
    """The value of ``--dpi``: a resolution [dots per inch] within FIGURE_DPI_RANGE (argparse
    names the flag in the one-line error)."""
    low, high = FIGURE_DPI_RANGE
    try:
        value = float(text)
    except ValueError:
        value = math.nan
    if not low <= value <= high:  # NaN fails too
        raise argparse.ArgumentTypeError(
            f"must be a number from {low:g} to {high:g} dots per inch, got {text!r}"
        )
    return value


def write_atomically(path: str, text: str, flag: str) -> None:
    """Write ``text`` to ``path``: all of it or, on any failure, nothing (the old file kept)."""
    write_text(path, text, flag)


def save_figure_atomically(
    fig: Figure, path: str, flag: str = "--png", dpi: float | None = None
) -> None:
    """Save a figure to ``path`` (format from its extension), all of it or nothing;
    ``dpi`` [dots per inch] for a raster (default: figures.saving's)."""
    from ..figures import saving  # noqa: PLC0415 (matplotlib only when drawing)

    saving.save(fig, path, flag, dpi=saving.DPI if dpi is None else dpi)


def text_output(path: str, text: str, flag: str, kind: str = "csv") -> Output:
    """``text`` (UTF-8) to ``path``: one file of a set written together."""
    return Output(path, flag, lambda handle: handle.write(text.encode()), kind)


def figure_output(fig: Figure, path: str, flag: str, dpi: float | None = None) -> Output:
    """A figure to ``path`` (format from its extension; ``dpi`` [dots per inch] for a
    raster, default figures.saving's): one file of a set written together."""
    from ..figures import saving  # noqa: PLC0415 (matplotlib only when drawing)

    writer = saving.figure_writer(fig, path, saving.DPI if dpi is None else dpi)
    return Output(path, flag, writer, "figure")


def add_dpi_option(parser: argparse.ArgumentParser) -> None:
    """``--dpi N``: the resolution of raster figures, checked before any work."""
    parser.add_argument(
        "--dpi",
        type=dots_per_inch,
        default=FIGURE_DPI,
        help=f"resolution of raster figures, {FIGURE_DPI_RANGE[0]:g}-{FIGURE_DPI_RANGE[1]:g} "
        f"dots per inch (default: {FIGURE_DPI:g}; study figures are 7.2 in wide)",
    )


def csv_text(header: Sequence[str], rows: Iterable[Sequence[object]]) -> str:
    """CSV with ``header``; floats written exactly (repr), booleans as true/false, text
    that a spreadsheet would run as a formula made inert (untrusted.spreadsheet_safe)."""
    buffer = io.StringIO()
    writer = csv.writer(buffer, lineterminator="\n")
    writer.writerow(header)
    for row in rows:
        writer.writerow([_cell(x) for x in row])
    return buffer.getvalue()


def _cell(value: object) -> object:
    if isinstance(value, bool):
        return str(value).lower()
    if isinstance(value, float):
        return repr(float(value))  # numpy's floats too, written as Python's
    if isinstance(value, str):
        return spreadsheet_safe(value)
    return value
