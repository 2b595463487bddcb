"""What ``limits`` and ``map`` share: lists and ranges of speeds and obliquities as typed,
and the archive that stores what they find."""

from __future__ import annotations

import argparse
import math

import numpy as np

from .. import limits as lim
from ..base.errors import ArchiveError
from ..model.results import Outcome
from ..storage.archive import Archive
from .common import UsageError
from .writer import Writer

OUTCOMES = tuple(o.label for o in Outcome)


def add_archive_options(p: argparse.ArgumentParser, default: str) -> None:
    p.add_argument(
        "--archive", metavar="FILE", help="also store the result in this HDF5 archive (show, "
        "compare read it)",
    )  # fmt: skip
    p.add_argument(
        "--name",
        help=f"the stored name (default {default}, with '/' as '_'; NAME.2, ... if taken)",
    )


def writable_archive(args: argparse.Namespace) -> Archive | None:
    """The --archive to store into, refused now if it could not take the result."""
    if args.name is not None and args.archive is None:
        raise UsageError("--name names what --archive stores; give --archive FILE")
    if args.archive is None:
        return None
    archive = Archive(args.archive)
    try:
        archive.check_writable()
    except ArchiveError as exc:  # a name too long, a read-only place, a damaged archive, ...
        raise UsageError(f"--archive: {exc}") from None
    return archive


def store(
    archive: Archive | None, name: str, found: lim.Limits | lim.OutcomeMap, out: Writer
) -> None:
    if archive is not None:
        stored = lim.archive_limits(archive, name.replace("/", "_"), found)
        out.say(f"archive: {archive.path} (limits/{stored})")


def finite_number(text: str, flag: str) -> float:
    try:
        value = float(text)
    except ValueError:
        raise UsageError(f"{flag} must be a number, got {text!r}") from None
    if not math.isfinite(value):
        raise UsageError(f"{flag} must be a finite number, got {text!r}")
    return value


def step(text: str, flag: str) -> float:
    """A tolerance or resolution: any number, NaN and inf included, which the finder's
    check refuses naming the allowed range (docs/limits.md)."""
    try:
        return float(text)
    except ValueError:
        raise UsageError(f"{flag} must be a number, got {text!r}") from None


def values(text: str, flag: str, unit: str) -> np.ndarray:
    """A comma list or START:STOP:N (N >= 1) [unit]."""
    parts = text.split(":")
    if len(parts) == 3:
        start, stop = finite_number(parts[0], flag), finite_number(parts[1], flag)
        try:
            count = int(parts[2])
        except ValueError:
            count = 0
        if not 1 <= count <= lim.MAX_SCAN_SCENES:
            raise UsageError(f"{flag}: N in START:STOP:N must be in [1, 1000000], got {parts[2]!r}")
        return np.linspace(start, stop, count)
    if len(parts) == 1 and text.strip():
        return np.array([finite_number(x, flag) for x in text.split(",")])
    raise UsageError(f"{flag} must be a comma list or START:STOP:N in {unit}, got {text!r}")


def span(text: str, flag: str) -> tuple[float, float]:
    start, _, stop = text.partition(":")
    return finite_number(start, flag), finite_number(stop, flag)


def is_range(text: str | None) -> bool:
    return text is None or text.count(":") == 1
