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

import contextlib
import io
import json
from collections.abc import Callable, Iterator, Sequence
from pathlib import Path
from typing import Protocol

import h5py
import numpy as np

from ..base.errors import ArchiveError
from ..base.parameters import Parameter
from ..base.untrusted import printable
from ..model.batch import CORE_COLUMNS, SceneBatch
from ..model.results import BatchResult
from ..run.variant import Variant
from .confined import directory, fsync_fd, shown_version, write_file
from .contained import check_contained, data_file, index_link_allowed
from .data_files import (  # noqa: F401 (data_directory and encoded: their public home)
    DataFiles,
    data_directory,
    encoded,
    read_index,
    remove_orphans,
)
from .hdf5 import seal
from .netcdf import write_run_file, write_scenes_file

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


@contextlib.contextmanager
def open_index(image: io.BytesIO, exists: bool, real: Path) -> Iterator[tuple[h5py.File, set[str]]]:
    """The index held in ``image`` (new if not ``exists``), open for writing in memory,
    with the data files it names; damage, another format version or anything that
    reaches outside the archive is an ArchiveError."""
    try:
        f = h5py.File(image, "r+" if exists else "w")
    except Exception as exc:  # noqa: BLE001 (h5py raises many kinds from a damaged file)
        raise ArchiveError(f"archive {real} cannot be opened: {_first_line(exc)}") from None
    with f:
        if exists:
            version = f.attrs.get("format_version")
            if f.attrs.get("format") != FORMAT or version != FORMAT_VERSION:
                raise ArchiveError(
                    f"archive {real} has format version {shown_version(version)}; this "
                    f"plateimpact appends to version {FORMAT_VERSION} only (plateimpact upgrade)"
                )
        named = check_contained(f, f"archive {real}", index_link_allowed) if exists else set()
        yield f, named


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
    return append_with(real, lambda f, files: add_run(
        f, files, study, variant, result, attributes, constants, run, overwrite
    ))  # fmt: skip


def add_run(
    f: h5py.File,
    files: DataFiles,
    study: StudyDefinition,
    variant: Variant,
    result: BatchResult,
    attributes: dict[str, object],
    constants: dict[str, Parameter],
    run: str | None = None,
    overwrite: bool = False,
) -> str:
    """Write the run's data file and link it from the open index ``f``."""
    name = run or variant.name
    real = files.real
    group = study_group(f, files, study, constants, real)
    runs = _group(group, "runs", f"archive {real}: study {printable(study.name)}")
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
        lambda handle: write_run_file(
            handle, study.scenes.columns, declared, study.plate_labels, result,
            {"study": study.name, "run": name, **attributes},
        ),
    )  # fmt: skip
    runs[name] = h5py.ExternalLink(target, "/")
    return name


def append_with(real: Path, write: Callable[[h5py.File, DataFiles], str]) -> str:
    """Extend the archive ``real`` (or create it) with ``write(index, files)``, which
    writes its data files through ``files`` and links them from the index, returning
    the name it stored them under. The index is read, extended in memory and written
    whole to a temporary beside it, fsync'ed and renamed over the original, each stage
    a fault point ("copy", "write", "flush", "fsync", "replace"); on any failure the
    new data files are removed again and the index is as it was. The caller holds the
    archive's lock."""
    with directory(real.parent, f"archive {real}: directory", follow=True) as parent:
        files = DataFiles(real, parent)
        try:
            fault_point("copy")
            old = read_index(parent, real)
            image = io.BytesIO(old or b"")
            with open_index(image, old is not None, real) as (f, named):
                remove_orphans(files, named)
                if old is None:
                    f.attrs["format"] = FORMAT
                    f.attrs["format_version"] = FORMAT_VERSION
                    f.attrs["description"] = (
                        f"plateimpact study archive (index; the runs' data in "
                        f"{files.directory.name}/); see docs/archive.md"
                    )
                fault_point("write")
                stored = write(f, files)
                if files.retired:  # the files the new index still names are kept
                    files.kept = check_contained(f, f"archive {real}", index_link_allowed)
            fault_point("flush")
            files.sync()
            write_file(parent, real.name, image.getbuffer(), real, lambda stage: fault_point(stage))
            fsync_fd(parent)
            files.commit()
        except BaseException:
            files.rollback()
            raise
        finally:
            files.close()
    return stored


def _group(parent: h5py.Group, name: str, what: str) -> h5py.Group:
    """The group ``name`` of ``parent``, which an index from someone else may hold as
    anything else."""
    found = parent.get(name)
    if not isinstance(found, h5py.Group):
        raise ArchiveError(f"{what}: {printable(name)} is not a group; the archive is damaged")
    return found


def _first_line(exc: BaseException) -> str:
    text = str(exc).strip().splitlines()
    return printable(text[0], 200) if text else type(exc).__name__


def check_same_scenes(scenes: h5py.Group, study: StudyDefinition, path: Path) -> None:
    """Refuse a study whose name is taken by one with other scenes (``scenes``: the
    stored study's scenes group or file)."""
    names = set(study.scenes.columns)
    stored = set(scenes) - {"plate_label", "plate", "scene"}  # labels; netCDF's dimension
    same = stored == names and all(_same(scenes.get(k), study.scenes.columns[k]) for k in names)
    if not same:
        raise ArchiveError(
            f"archive {path} already holds a different study named {study.name!r}; rename the study"
        )


def _same(stored: object, values: np.ndarray) -> bool:
    """Whether the stored dataset holds ``values`` (its shape compared first: a shape from
    someone else is not read whole before it is known to be the study's)."""
    if not isinstance(stored, h5py.Dataset) or stored.shape != values.shape:
        return False
    return bool(np.array_equal(stored[()], values))


def study_group(
    f: h5py.File,
    files: DataFiles,
    study: StudyDefinition,
    constants: dict[str, Parameter],
    path: Path,
) -> h5py.Group:
    """The study's group in the index, made (with its scenes' data file) if new."""
    if study.name in f:
        what = f"archive {path}: study {printable(study.name)}"
        group = _group(f, study.name, f"archive {path}")
        link = group.get("scenes", getlink=True)
        if not isinstance(link, h5py.ExternalLink):
            raise ArchiveError(f"{what} has no link to its scenes; the archive is damaged")
        # by its name in the archive's own data directory now (a renamed archive too)
        with data_file(files.directory, link.filename, f"{what}: scenes") as scenes:
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
        lambda handle: write_scenes_file(
            handle, study.scenes.columns, declared, study.plate_labels,
            {"study": study.name, "description": study.description},
        ),
    )  # fmt: skip
    group["scenes"] = h5py.ExternalLink(target, "/")
    group.create_group("runs", track_order=True)
    return group


def _scene_column(name: str, constants: dict[str, Parameter]) -> Parameter:
    """The declaration of a scene column: a core column or a plate constant, as
    ``constants`` (the run's plug-ins', then its registry's: the caller's) declare it."""
    declared = CORE_COLUMNS.get(name) or constants.get(name)
    return declared or Parameter(name, f"plate constant {name} (no installed plug-in declares it)")
