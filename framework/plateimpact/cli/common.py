"""What every command shares: the one-line error, output files written atomically."""

from __future__ import annotations

import argparse
import csv
import io
import math
import sys
from collections.abc import Iterable, Sequence
from typing import TYPE_CHECKING, Any, NoReturn

from ..errors import PlateImpactError
from ..storage.output import FIGURE_DPI, FIGURE_DPI_RANGE, OutputError, check_output, write_text

if TYPE_CHECKING:
    from matplotlib.figure import Figure


class UsageError(PlateImpactError):
    """A command-line argument is malformed."""


class Parser(argparse.ArgumentParser):
    """An argument parser whose errors are one line and exit code 2, without the usage."""

    def __init__(self, *args: Any, **kwargs: Any) -> None:
        kwargs.setdefault("allow_abbrev", False)  # a mistyped prefix is an error, not a guess
        super().__init__(*args, **kwargs)

    def error(self, message: str) -> NoReturn:
        self.exit(2, f"plateimpact: error: {message}\n")


def check_directory(path: str | None, flag: str, kind: str = "csv") -> None:
    """Refuse, before any work is done, an output ``path`` that could not be written
    (storage.output.check_output: missing or unwritable directory, a directory, not a
    regular file, read-only, a figure format matplotlib cannot write)."""
    if path is not None:
        check_output(path, flag, kind)


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
    ``dpi`` [dots per inch] for a raster (default: plotting's)."""
    from .. import plotting  # noqa: PLC0415 (matplotlib only when drawing)

    plotting.save(fig, path, flag, dpi=plotting.DPI if dpi is None else dpi)


def add_dpi_option(parser: argparse.ArgumentParser) -> None:
    """``--dpi N``: the resolution of raster figures, checked before any work."""
    parser.add_argument(
        "--dpi",
        type=dots_per_inch,
        default=FIGURE_DPI,
        help=f"resolution of raster figures, {FIGURE_DPI_RANGE[0]:g}-{FIGURE_DPI_RANGE[1]:g} "
        f"dots per inch (default: {FIGURE_DPI:g}; study figures are 7.2 in wide)",
    )


def write_stdout(text: str) -> None:
    """Print ``text``; a standard output that cannot take it (a full device) is one line."""
    try:
        sys.stdout.write(text)
        sys.stdout.flush()
    except BrokenPipeError:
        raise
    except OSError as exc:
        raise OutputError(f"standard output: cannot write: {exc.strerror}") from None


def csv_text(header: Sequence[str], rows: Iterable[Sequence[object]]) -> str:
    """CSV with ``header``; floats written exactly (repr), booleans as true/false."""
    buffer = io.StringIO()
    writer = csv.writer(buffer, lineterminator="\n")
    writer.writerow(header)
    for row in rows:
        writer.writerow(
            [
                str(x).lower()
                if isinstance(x, bool)
                else repr(float(x))
                if isinstance(x, float)
                else x
                for x in row
            ]
        )
    return buffer.getvalue()
