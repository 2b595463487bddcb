"""Appending a run to an archive: the steps, each a fault point, and the HDF5 layout
of a study and a run (docs/archive.md). The caller holds the archive's lock."""

from __future__ import annotations

import json
import os
import shutil
import tempfile
from collections.abc import Callable, Sequence
from pathlib import Path
from typing import Protocol

import h5py
import numpy as np

from ..batch import CORE_COLUMNS, SceneBatch
from ..errors import ArchiveError
from ..parameters import Parameter
from ..registry import default_registry
from ..results import CRATER_FIELDS, RESULT_FIELDS, TRAJECTORY_FIELDS, BatchResult
from ..variant import Variant
from .hdf5 import seal, write_declared, write_ragged
from .output import fsync_directory, keep_mode

FORMAT, FORMAT_VERSION = "plateimpact-archive", 1


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


def fault_point(stage: str) -> None:
    """Called at each stage of an append ("copy", "write", "flush", "fsync", "replace",
    then "unlock" by the archive, with the run in and the lock still held): nothing,
    unless a test replaces it to fail or crash there deterministically."""


def append(
    real: Path,
    study: StudyDefinition,
    variant: Variant,
    result: BatchResult,
    attributes: dict[str, object],
    constants: dict[str, Parameter],
) -> str:
    """Add one run to the archive file ``real`` (or create it): a copy is extended and
    renamed over the original, so a crash at any stage leaves the old file whole.
    Returns the run's name in its study."""

    def add_run(f: h5py.File) -> str:
        group = study_group(f, study, constants, real)
        runs = group.require_group("runs")
        run, k = variant.name, 1
        while run in runs:
            k += 1
            run = f"{variant.name}.{k}"
        write_run(runs.create_group(run), result, attributes)
        return run

    return append_with(real, add_run)


def append_with(real: Path, write: Callable[[h5py.File], str]) -> str:
    """Extend the archive file ``real`` (or create it) with ``write(file)``, which adds
    its groups to the open copy and returns the name it stored them under: the archive
    is copied, the copy extended, fsync'ed and renamed over the original, each stage a
    fault point. The caller holds the archive's lock."""
    for stale in real.parent.glob(f".{real.name}.*.tmp"):  # left by killed writers
        stale.unlink(missing_ok=True)  # we hold the lock: no live writer uses one
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
            if "format" not in f.attrs:
                f.attrs["format"] = FORMAT
                f.attrs["format_version"] = FORMAT_VERSION
                f.attrs["description"] = "plateimpact study archive; see docs/archive.md"
            stored = write(f)
            fault_point("flush")
        with open(temporary, "rb+") as handle:
            fault_point("fsync")
            os.fsync(handle.fileno())
        keep_mode(str(temporary), real)
        fault_point("replace")
        os.replace(temporary, real)
        fsync_directory(real.parent)
    finally:
        temporary.unlink(missing_ok=True)
    return stored


def check_same_scenes(group: h5py.Group, study: StudyDefinition, path: Path) -> None:
    scenes, names = group["scenes"], set(study.scenes.columns)
    same = set(scenes) - {"plate_label"} == names and all(
        np.array_equal(scenes[k][()], study.scenes.columns[k]) for k in names
    )
    if not same:
        raise ArchiveError(
            f"archive {path} already holds a different study named {study.name!r}; rename the study"
        )


def study_group(
    f: h5py.File, study: StudyDefinition, constants: dict[str, Parameter], path: Path
) -> h5py.Group:
    if study.name in f:
        group = f[study.name]
        check_same_scenes(group, study, path)
        return group
    group = f.create_group(study.name)
    group.attrs["description"] = study.description
    group.attrs["variants"] = json.dumps([json.loads(v.to_json()) for v in study.variants])
    labels = sorted(set(study.plate_labels))
    group.attrs["plate_labels"] = json.dumps(labels)
    seal(group)
    scenes = group.create_group("scenes")
    scenes.attrs["count"] = study.scenes.size
    for name, values in study.scenes.columns.items():
        write_declared(scenes, _scene_column(name, constants), values)
    index = np.array([labels.index(label) for label in study.plate_labels], dtype=np.int32)
    label_field = Parameter("plate_label", "index into the study's plate_labels attribute")
    write_declared(scenes, label_field, index)
    return group


def write_run(group: h5py.Group, result: BatchResult, attributes: dict[str, object]) -> None:
    for key, value in attributes.items():
        group.attrs[key] = value
    seal(group)
    results = group.create_group("results")
    for name, declared in RESULT_FIELDS.items():
        write_declared(results, declared, result.columns[name])
    if result.craters is not None:
        write_ragged(
            group.create_group("crater"), result.craters, "counts", "lateral", CRATER_FIELDS
        )
    if result.trajectory is not None:
        state_units = json.loads(str(attributes.get("failure_state_units", "{}")))
        fields = {k: _trajectory_field(k, state_units) for k in result.trajectory.values}
        write_ragged(group.create_group("trajectory"), result.trajectory, "count", "time", fields)


def _scene_column(name: str, constants: dict[str, Parameter]) -> Parameter:
    """The declaration of a scene column: a core column or a plate constant, as the run's
    plug-ins (else any registered plug-in) declare it."""
    declared = CORE_COLUMNS.get(name) or constants.get(name)
    declared = declared or default_registry().plate_constants.get(name)
    return declared or Parameter(name, f"plate constant {name} (no installed plug-in declares it)")


def _trajectory_field(name: str, state_units: dict[str, str]) -> Parameter:
    if name in TRAJECTORY_FIELDS:
        return TRAJECTORY_FIELDS[name]
    state = name.removeprefix("failure_")
    return Parameter(
        name, f"failure-model state {state!r} (NaN before failure)", state_units.get(state, "1")
    )
