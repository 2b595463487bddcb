"""What every command shares: the one-line error, output files written atomically."""

from __future__ import annotations

import argparse
import csv
import io
import os
import tempfile
from collections.abc import Iterable, Sequence
from typing import TYPE_CHECKING, Any, NoReturn

from ..errors import PlateImpactError

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


def check_directory(path: str | None, flag: str) -> None:
    """Refuse an output path in a missing directory before any work is done."""
    if path is not None and not os.path.isdir(os.path.dirname(os.path.abspath(path))):
        raise UsageError(
            f"{flag}: directory {os.path.dirname(os.path.abspath(path))!r} does not exist"
        )


def write_atomically(path: str, text: str, flag: str) -> None:
    """Write ``text`` to ``path`` so that no partial file is ever left behind."""
    check_directory(path, flag)
    directory = os.path.dirname(os.path.abspath(path))
    fd, tmp = tempfile.mkstemp(dir=directory, prefix=".plateimpact-", suffix=".tmp")
    try:
        with os.fdopen(fd, "w", newline="") as handle:
            handle.write(text)
        os.replace(tmp, path)
    except BaseException:
        if os.path.exists(tmp):
            os.unlink(tmp)
        raise


def save_figure_atomically(fig: Figure, path: str) -> None:
    """Save a figure to ``path`` [PNG] so that no partial file is left behind."""
    from .. import plotting  # noqa: PLC0415 (matplotlib only when drawing)

    directory = os.path.dirname(os.path.abspath(path))
    fd, tmp = tempfile.mkstemp(dir=directory, prefix=".plateimpact-", suffix=".png")
    os.close(fd)
    try:
        plotting.save(fig, tmp)
        os.replace(tmp, path)
    finally:
        if os.path.exists(tmp):
            os.unlink(tmp)


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
