"""Rewriting a format-1 archive (one file) as format 2 (an index and data files).

Under the archive's lock for the whole upgrade (no other writer can come between), every
run, in the order written and under its name, and every stored record is written to a
data file of the new archive, each bit for bit as stored, and the new index is built in
memory. Only then is the format-1 file kept as ``ARCHIVE.format1.h5`` (a hard link to
it, or a copy where the filesystem has none; it is never written) and the path replaced
by the new index in one rename. So the path holds an archive at every instant: the
format-1 one until the rename, the format-2 one after. A failure or a crash at any
stage before the rename leaves the format-1 archive at its path, as it was, with data
files no index names, which the next upgrade removes before it starts again; after it,
the upgrade is done.
"""

from __future__ import annotations

import contextlib
import errno
import functools
import io
import os
from pathlib import Path
from typing import BinaryIO

import h5py

from ..base.errors import ArchiveError
from ..base.untrusted import printable
from ..registry.plugin_registry import PluginRegistry
from . import stored_attributes as typed
from .append import FORMAT, FORMAT_VERSION, add_run
from .archive import WAIT, Archive
from .confined import check_lengths, directory, fsync_fd, open_regular, write_file
from .data_files import DataFiles, encoded, remove_orphans
from .lock import locked
from .output import unwritable
from .records import LIMITS


def fault_point(stage: str) -> None:
    """Called at each stage of an upgrade ("run" after each run's data file, "record"
    after each record's, "built" with the new index made in memory, "kept" with the
    format-1 file kept under its new name, "replaced" with the new index at the path):
    nothing, unless a test replaces it to fail or crash there deterministically."""


def backup_path(path: Path) -> Path:
    return path.with_name(f"{path.name}.format1{path.suffix or '.h5'}")


def upgrade(path: str | os.PathLike[str], *, registry: PluginRegistry, wait: float = WAIT) -> Path:
    """Rewrite the format-1 archive at ``path`` as format 2 (the plate constants' units
    and descriptions as ``registry`` declares them); returns where the format-1 file was
    kept. ArchiveError (one line) if it is not a format-1 archive, if the place
    for the old file is taken by another file, or if another writer keeps the archive
    longer than ``wait`` [s]. Rerun after a failure or a crash, it completes."""
    old = Archive(path, wait=wait)
    kept = backup_path(old.real)
    label = f"archive {printable(old.path, 80)}"
    check_lengths(old.path, old.real, label, extra=len(kept.name) - len(old.real.name))
    if not os.access(old.real.parent, os.W_OK | os.X_OK):
        raise ArchiveError(f"{label}: directory {old.real.parent} is {unwritable(old.real.parent)}")
    replaced: list[bool] = []
    try:
        with locked(old.path, old.real, old.lock_path, wait):
            version = old.version()
            if version != 1:
                raise ArchiveError(f"{label} has format version {version}: nothing to upgrade")
            with directory(old.real.parent, f"{label}: directory", follow=True) as parent:
                _check_kept(parent, old.real, kept, label)
                _rewrite(old, parent, kept, replaced, registry)
    except ArchiveError:
        raise
    except OSError as exc:  # a full disk, a lost mount
        state = "the upgrade is done" if replaced else "the archive is unchanged"
        raise ArchiveError(f"{label}: cannot upgrade: {exc.strerror or exc} ({state})") from None
    return kept


def _check_kept(parent: int, real: Path, kept: Path, label: str) -> None:
    """Refuse a file at ``kept`` other than the format-1 file itself (a hard link an
    upgrade made before it was stopped) or a whole copy of it."""
    try:
        there = os.stat(kept.name, dir_fd=parent, follow_symlinks=False)
    except FileNotFoundError:
        return
    ours = os.stat(real.name, dir_fd=parent, follow_symlinks=False)
    if (there.st_dev, there.st_ino) == (ours.st_dev, ours.st_ino):
        return
    if there.st_size == ours.st_size and _read(parent, kept, label) == _read(parent, real, label):
        return
    raise ArchiveError(f"{label}: {kept} is in the way; move it and upgrade again")


def _read(parent: int, path: Path, label: str) -> bytes:
    with open_regular(path.name, f"{label}: {path}", dir_fd=parent) as handle:
        return handle.read()


def _rewrite(
    old: Archive, parent: int, kept: Path, replaced: list[bool], registry: PluginRegistry
) -> None:
    """Write the new archive's data files and index, keep the format-1 file, replace the
    path by the new index (``replaced`` gets True once it has)."""
    files = DataFiles(old.real, parent)
    try:
        remove_orphans(files, set())  # a format-1 index names no data file
        image = io.BytesIO()
        with h5py.File(image, "w") as f:
            f.attrs["format"] = FORMAT
            f.attrs["format_version"] = FORMAT_VERSION
            f.attrs["description"] = (
                f"plateimpact study archive (index; the runs' data in {files.directory.name}/"
                "); see docs/archive.md"
            )
            _copy_runs(old, f, files, registry)
            _copy_records(old, f, files)
        fault_point("built")
        files.sync()
        _keep(parent, old.real, kept)
        fault_point("kept")
        write_file(parent, old.real.name, image.getbuffer(), old.real)
        replaced.append(True)
        fsync_fd(parent)
        fault_point("replaced")
    except BaseException:
        if not replaced:  # the new index names them once it is in place
            files.rollback()
        raise
    finally:
        files.close()


def _copy_runs(old: Archive, f: h5py.File, files: DataFiles, registry: PluginRegistry) -> None:
    constants = dict(registry.plate_constants)
    for run in old.runs():
        study_name, name = run.split("/", 1)
        study = old.study(study_name)
        attributes = old.raw_attributes(run)
        variant = typed.run_variant(attributes, f"archive {old.path}: run {printable(run)}")
        add_run(f, files, study, variant, old.results(run), attributes, constants, name)
        fault_point("run")


def _copy_records(old: Archive, f: h5py.File, files: DataFiles) -> None:
    names = old.limits_names()
    if not names:
        return
    for name in names:
        old.record(name)  # its digest checked
    with old._open() as source:  # checked to reach no other file
        attributes = dict(source[LIMITS].attrs)
        copies = [encoded(functools.partial(_copy_record, source[f"{LIMITS}/{n}"])) for n in names]
    container = f.create_group(LIMITS, track_order=True)
    for key, value in attributes.items():
        container.attrs[key] = value
    for name, data in zip(names, copies, strict=True):
        target = files.new(f"{LIMITS}.{name}", functools.partial(_write, data))
        container[name] = h5py.ExternalLink(target, "/")
        fault_point("record")


def _write(data: bytes, handle: BinaryIO) -> None:
    handle.write(data)


def _copy_record(group: h5py.Group, handle: BinaryIO) -> None:
    """A copy of the format-1 record ``group`` (its datasets with their attributes, as
    stored) as the root of a file of its own."""
    with h5py.File(handle, "w") as copied:
        for key in group:
            group.file.copy(group[key], copied, name=key)
        for key, value in group.attrs.items():
            copied.attrs[key] = value


def _keep(parent: int, real: Path, kept: Path) -> None:
    """Keep the format-1 file as ``kept``: a hard link (it is never written again), or a
    whole copy written atomically where the filesystem has no hard links."""
    try:
        os.link(real.name, kept.name, src_dir_fd=parent, dst_dir_fd=parent, follow_symlinks=False)
    except FileExistsError:
        return  # checked before: the same file, or a whole copy of it
    except OSError as exc:
        if exc.errno not in (
            errno.EPERM,
            errno.EXDEV,
            errno.ENOTSUP,
            errno.EMLINK,
            errno.EOPNOTSUPP,
        ):
            raise
        write_file(parent, kept.name, _read(parent, real, f"archive {real}"), real)
    with contextlib.suppress(OSError):
        fsync_fd(parent)
