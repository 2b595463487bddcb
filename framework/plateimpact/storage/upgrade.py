"""Rewriting a format-1 archive (one file) as format 2 (an index and data files).

The format-1 file is first renamed aside (``ARCHIVE.format1.h5``, an atomic rename: it
is never written), then every run, in the order written and under its name, and every
stored record is appended to a new archive at the old path, each bit for bit as stored.
A failure or crash midway leaves the format-1 file whole beside a partial new archive;
rerunning says so.
"""

from __future__ import annotations

import functools
import os
from pathlib import Path
from typing import BinaryIO

import h5py

from ..errors import ArchiveError
from ..registry import default_registry
from ..variant import Variant
from .append import append_with
from .archive import Archive
from .data_files import DataFiles
from .records import LIMITS


def backup_path(path: Path) -> Path:
    return path.with_name(f"{path.name}.format1{path.suffix or '.h5'}")


def upgrade(path: str | os.PathLike[str]) -> Path:
    """Rewrite the format-1 archive at ``path`` as format 2; returns where the format-1
    file was kept. ArchiveError (one line) if it is not a format-1 archive, or if the
    place for the old file is taken."""
    old = Archive(path)
    version = old.version()
    if version != 1:
        raise ArchiveError(f"archive {old.path} has format version {version}: nothing to upgrade")
    if not os.access(old.real.parent, os.W_OK | os.X_OK):
        raise ArchiveError(f"archive {old.path}: directory {old.real.parent} is not writable")
    kept = backup_path(old.real)
    if kept.exists():
        raise ArchiveError(f"archive {old.path}: {kept} is in the way; move it and upgrade again")
    if old.data.exists():
        raise ArchiveError(
            f"archive {old.path}: {old.data} is in the way; move it and upgrade again"
        )
    os.replace(old.real, kept)
    source, target = Archive(kept), Archive(old.real, wait=old.wait)
    constants = dict(default_registry().plate_constants)
    for run in source.runs():
        study_name, name = run.split("/", 1)
        study = source.study(study_name)
        attributes = source.raw_attributes(run)
        variant = Variant.from_json(str(attributes["variant"]))
        target.append_run(study, variant, source.results(run), attributes, constants, run=name)
    for name in source.limits_names():
        source.record(name)  # its digest checked
        write = functools.partial(_copy_record, kept=kept, name=name)
        target._append(
            functools.partial(append_with, write=write),
            lambda stored: f"{LIMITS}/{stored}", name, f"{LIMITS}.{name}",
        )  # fmt: skip
    return kept


def _copy_record(f: h5py.File, files: DataFiles, *, kept: Path, name: str) -> str:
    """Link a copy of the format-1 record ``name`` (its datasets with their attributes,
    as stored) from the new index ``f``."""

    def copy(where: BinaryIO) -> None:
        with h5py.File(kept, "r") as source, h5py.File(where, "w") as copied:
            group = source[f"{LIMITS}/{name}"]
            for key in group:
                source.copy(group[key], copied, name=key)
            for key, value in group.attrs.items():
                copied.attrs[key] = value

    if LIMITS not in f:
        container = f.create_group(LIMITS, track_order=True)
        with h5py.File(kept, "r") as source:
            for key, value in source[LIMITS].attrs.items():
                container.attrs[key] = value
    f[LIMITS][name] = h5py.ExternalLink(files.new(f"{LIMITS}.{name}", copy), "/")
    return name
