"""Appending to an archive: the steps, each a fault point, and the layout of a study and
a run (docs/archive.md). The caller holds the archive's lock.

Format 2 keeps each run's numbers in a data file of its own (``ARCHIVE.d/*.nc``, written
once, never changed) and names them in a small index (``ARCHIVE``, HDF5 external links),
so an append writes its run once and rewrites only the index: its cost does not grow
with the runs already there. The index is replaced atomically (copy, extend, fsync,
rename), as the whole file was in format 1, so a crash at any stage leaves the previous
index, and every run it names, untouched; a data file that no index names (its writer
died before the rename) is removed by the next writer.
"""

from __future__ import annotations

import json
import os
import re
import secrets
import shutil
import tempfile
from collections.abc import Callable, Sequence
from pathlib import Path, PurePath
from typing import Protocol

import h5py
import numpy as np

from ..batch import CORE_COLUMNS, SceneBatch
from ..errors import ArchiveError
from ..parameters import Parameter
from ..registry import default_registry
from ..results import BatchResult
from ..variant import Variant
from .hdf5 import seal
from .netcdf import write_run_file, write_scenes_file
from .output import fsync_directory, keep_mode

FORMAT, FORMAT_VERSION = "plateimpact-archive", 2
#: Versions this plateimpact reads; it appends to FORMAT_VERSION only.
READABLE_VERSIONS = (1, 2)


class StudyDefinition(Protocol):
    """What an archive stores of a study (:class:`plateimpact.Study` is one)."""

    @property
    def name(self) -> str: ...
    @property
    def scenes(self) -> SceneBatch: ...
    @property
    def variants(self) -> Sequence[Variant]: ...
    @property
    def plate_labels(self) -> Sequence[str]: ...
    @property
    def description(self) -> str: ...


class RunExistsError(ArchiveError):
    """The run's name is taken in its study: keep it (resume), replace it (overwrite) or
    store the new run under another name; never a silent ``NAME.2``."""


def fault_point(stage: str) -> None:
    """Called at each stage of an append ("copy", "write", "flush", "fsync", "replace",
    then "unlock" by the archive, with the run in and the lock still held): nothing,
    unless a test replaces it to fail or crash there deterministically."""


def data_directory(real: Path) -> Path:
    """Where the data files of the archive (index) ``real`` live: ``ARCHIVE.d``."""
    return real.with_name(f"{real.name}.d")


def _slug(text: str) -> str:
    return re.sub(r"[^A-Za-z0-9._+-]+", "_", text)[:60] or "_"


class DataFiles:
    """The data files one append writes: each complete and fsync'ed before the index
    names it; removed again if the append fails; files it retires (a run replaced by
    ``overwrite``) removed only once the new index is in place."""

    def __init__(self, real: Path) -> None:
        self.real = real
        self.directory = data_directory(real)
        self.written: list[Path] = []
        self.retired: list[Path] = []

    def new(self, stem: str, write: Callable[[Path], None]) -> str:
        """Write a data file through ``write(path)``; returns its name relative to the
        index's directory (the external link's target)."""
        if not self.directory.is_dir():
            self.directory.mkdir()
            if self.real.exists():  # whoever may read the index may read its data
                readers = os.stat(self.real).st_mode & 0o044
                os.chmod(self.directory, 0o700 | readers | readers >> 2)
        name = f"{_slug(stem)}.{secrets.token_hex(4)}.nc"
        fd, temporary = tempfile.mkstemp(dir=self.directory, prefix=f".{name}.", suffix=".tmp")
        os.close(fd)
        try:
            write(Path(temporary))
            with open(temporary, "rb+") as handle:
                os.fsync(handle.fileno())
            keep_mode(temporary, self.real)
            os.replace(temporary, self.directory / name)
        finally:
            Path(temporary).unlink(missing_ok=True)
        self.written.append(self.directory / name)
        return f"{self.directory.name}/{name}"

    def retire(self, target: str) -> None:
        self.retired.append(self.directory / PurePath(target).name)

    def rollback(self) -> None:
        for path in self.written:
            path.unlink(missing_ok=True)

    def commit(self) -> None:
        for path in self.retired:
            path.unlink(missing_ok=True)


def linked_files(f: h5py.File) -> set[str]:
    """The data files the index ``f`` names (its external links' targets)."""
    found: set[str] = set()

    def visit(name: str, link: object) -> None:
        if isinstance(link, h5py.ExternalLink):
            found.add(link.filename)

    f.visititems_links(visit)
    return found


def _link_count(f: h5py.File) -> int:
    """How many data files the index ``f`` names: each study's scenes and runs, each
    record (counted per group, without walking the links)."""
    count = 0
    for name in f:
        group = f[name]
        if "scenes" in group:
            count += 1 + len(group.get("runs", ()))
        else:
            count += len(group)
    return count


def remove_orphans(real: Path) -> None:
    """Remove what killed writers left: temporaries beside the index and in its data
    directory, and data files no index names. The caller holds the lock."""
    for stale in real.parent.glob(f".{real.name}.*.tmp"):
        stale.unlink(missing_ok=True)  # we hold the lock: no live writer uses one
    directory = data_directory(real)
    if not directory.is_dir():
        return
    present = list(directory.iterdir())
    named = set()
    if real.exists():
        with h5py.File(real, "r") as f:
            data = [p for p in present if p.suffix == ".nc"]
            if len(data) == _link_count(f) and not any(p.name.endswith(".tmp") for p in present):
                return  # one file per link: nothing left behind (the usual case, cheaply)
            named = {PurePath(target).name for target in linked_files(f)}  # by file name:
            # the index may have been renamed
    for path in present:
        orphan = path.name.endswith(".tmp") or (path.suffix == ".nc" and path.name not in named)
        if orphan and path.is_file():
            path.unlink(missing_ok=True)


def append(
    real: Path,
    study: StudyDefinition,
    variant: Variant,
    result: BatchResult,
    attributes: dict[str, object],
    constants: dict[str, Parameter],
    run: str | None = None,
    overwrite: bool = False,
) -> str:
    """Add one run to the archive ``real`` (or create it) as ``run`` (default: the
    variant's name): its data file, then the index. A run of that name is replaced with
    ``overwrite``, else refused (:class:`RunExistsError`). Returns the run's name."""
    name = run or variant.name

    def add_run(f: h5py.File, files: DataFiles) -> str:
        group = study_group(f, files, study, constants, real)
        runs = group["runs"]
        if name in runs:
            if not overwrite:
                raise RunExistsError(
                    f"archive {real} already has run {study.name}/{name}: keep it (resume), "
                    "replace it (overwrite) or name the new run otherwise"
                )
            old = runs.get(name, getlink=True)
            if isinstance(old, h5py.ExternalLink):
                files.retire(old.filename)
            del runs[name]
        declared = {k: _scene_column(k, constants) for k in study.scenes.columns}
        target = files.new(
            f"{study.name}.{name}",
            lambda path: write_run_file(
                path, study.scenes.columns, declared, study.plate_labels, result,
                {"study": study.name, "run": name, **attributes},
            ),
        )  # fmt: skip
        runs[name] = h5py.ExternalLink(target, "/")
        return name

    return append_with(real, add_run)


def append_with(real: Path, write: Callable[[h5py.File, DataFiles], str]) -> str:
    """Extend the archive ``real`` (or create it) with ``write(index, files)``, which
    writes its data files through ``files`` and links them from the open copy of the
    index, returning the name it stored them under: the index is copied, extended,
    fsync'ed and renamed over the original, each stage a fault point; on any failure
    the new data files are removed again. The caller holds the archive's lock."""
    remove_orphans(real)
    files = DataFiles(real)
    fd, name = tempfile.mkstemp(
        dir=real.parent, prefix=f".{real.name}.{os.getpid()}.", suffix=".tmp"
    )
    os.close(fd)
    temporary = Path(name)
    try:
        fault_point("copy")
        if real.exists():
            shutil.copyfile(real, temporary)
        fault_point("write")
        with h5py.File(temporary, "a") as f:
            if f.attrs.get("format_version", FORMAT_VERSION) != FORMAT_VERSION:
                raise ArchiveError(
                    f"archive {real} has format version {f.attrs['format_version']}; this "
                    f"plateimpact appends to version {FORMAT_VERSION} only (plateimpact upgrade)"
                )
            if "format" not in f.attrs:
                f.attrs["format"] = FORMAT
                f.attrs["format_version"] = FORMAT_VERSION
                f.attrs["description"] = (
                    f"plateimpact study archive (index; the runs' data in {files.directory.name}/"
                    "); see docs/archive.md"
                )
            stored = write(f, files)
            fault_point("flush")
        with open(temporary, "rb+") as handle:
            fault_point("fsync")
            os.fsync(handle.fileno())
        if files.written:
            fsync_directory(files.directory)
        keep_mode(str(temporary), real)
        fault_point("replace")
        os.replace(temporary, real)
        fsync_directory(real.parent)
    except BaseException:
        files.rollback()
        raise
    finally:
        temporary.unlink(missing_ok=True)
    files.commit()
    return stored


def check_same_scenes(scenes: h5py.Group, study: StudyDefinition, path: Path) -> None:
    """Refuse a study whose name is taken by one with other scenes (``scenes``: the
    stored study's scenes group or file)."""
    names = set(study.scenes.columns)
    stored = set(scenes) - {"plate_label", "plate", "scene"}  # labels; netCDF's dimension
    same = stored == names and all(
        np.array_equal(scenes[k][()], study.scenes.columns[k]) for k in names
    )
    if not same:
        raise ArchiveError(
            f"archive {path} already holds a different study named {study.name!r}; rename the study"
        )


def study_group(
    f: h5py.File,
    files: DataFiles,
    study: StudyDefinition,
    constants: dict[str, Parameter],
    path: Path,
) -> h5py.Group:
    """The study's group in the index, made (with its scenes' data file) if new."""
    if study.name in f:
        group = f[study.name]
        link = group.get("scenes", getlink=True)
        with h5py.File(path.parent / link.filename, "r") as scenes:
            check_same_scenes(scenes, study, path)
        return group
    group = f.create_group(study.name)
    group.attrs["description"] = study.description
    group.attrs["variants"] = json.dumps([json.loads(v.to_json()) for v in study.variants])
    labels = sorted(set(study.plate_labels))
    group.attrs["plate_labels"] = json.dumps(labels)
    seal(group)
    declared = {k: _scene_column(k, constants) for k in study.scenes.columns}
    target = files.new(
        f"{study.name}.scenes",
        lambda where: write_scenes_file(
            where, study.scenes.columns, declared, study.plate_labels,
            {"study": study.name, "description": study.description},
        ),
    )  # fmt: skip
    group["scenes"] = h5py.ExternalLink(target, "/")
    group.create_group("runs", track_order=True)
    return group


def _scene_column(name: str, constants: dict[str, Parameter]) -> Parameter:
    """The declaration of a scene column: a core column or a plate constant, as the run's
    plug-ins (else any registered plug-in) declare it."""
    declared = CORE_COLUMNS.get(name) or constants.get(name)
    declared = declared or default_registry().plate_constants.get(name)
    return declared or Parameter(name, f"plate constant {name} (no installed plug-in declares it)")
