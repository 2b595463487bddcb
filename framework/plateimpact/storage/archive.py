"""HDF5 archives of study runs (schema: docs/archive.md).

One file holds any number of studies; each study holds its scenes once and any number
of runs. A run is appended by copying the archive to a temporary file, adding the run
there and renaming the copy over the original (``os.replace``), so a crash at any point
leaves the previous archive, with every finished run, untouched. A lock file next to
the archive names the writing process; while it lives, opening the archive is refused.
"""

from __future__ import annotations

import contextlib
import json
import os
import shutil
from collections.abc import Iterator, Sequence
from pathlib import Path
from typing import Protocol

import attrs
import h5py
import numpy as np

from ..batch import CORE_COLUMNS, SceneBatch
from ..errors import ArchiveError, PlateImpactError, UnknownNameError
from ..parameters import Parameter
from ..ragged import Ragged
from ..registry import default_registry
from ..results import CRATER_FIELDS, RESULT_FIELDS, TRAJECTORY_FIELDS, BatchResult
from ..variant import Variant
from .hdf5 import SEAL, digest, plain_attributes, seal, write_declared, write_ragged
from .lock import check_not_busy, fsync_directory, locked

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


@attrs.frozen(eq=False)
class ArchivedStudy:
    """A study as an archive holds it: its name, scenes [SI], variants, one plate label
    per scene and description (``plateimpact.Study.from_archive`` makes it a Study)."""

    name: str
    scenes: SceneBatch
    variants: tuple[Variant, ...]
    plate_labels: tuple[str, ...]
    description: str


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


class Archive:
    """An HDF5 archive of studies and their runs at ``path``.

    Runs are named ``STUDY/RUN``; the bare ``RUN`` is enough when one study has it.
    Every failure to open or read (missing directory, not HDF5, checksum mismatch, a
    live writer) raises :class:`ArchiveError` with a one-line message.
    """

    def __init__(self, path: str | os.PathLike[str]) -> None:
        self.path = Path(path)
        self.lock_path = self.path.with_name(self.path.name + ".lock")

    # -- writing ---------------------------------------------------------------------

    def check_writable(self) -> None:
        """Refuse early what :meth:`append_run` would refuse after a long run."""
        if not self.path.parent.is_dir():
            raise ArchiveError(f"archive {self.path}: directory {self.path.parent} does not exist")
        check_not_busy(self.path, self.lock_path)
        if self.path.exists():
            with self._open():
                pass

    def append_run(
        self,
        study: StudyDefinition,
        variant: Variant,
        result: BatchResult,
        attributes: dict[str, object],
        constants: dict[str, Parameter] | None = None,
    ) -> str:
        """Add one finished run of ``study`` (atomically); returns its name ``STUDY/RUN``.

        ``constants`` are the declarations of the plate constants the run's plug-ins read
        (units and descriptions of the scene datasets)."""
        if not self.path.parent.is_dir():
            raise ArchiveError(f"archive {self.path}: directory {self.path.parent} does not exist")
        with locked(self.path, self.lock_path):
            self._remove_stale_copies()
            temporary = self.path.with_name(f".{self.path.name}.{os.getpid()}.tmp")
            try:
                if self.path.exists():
                    with self._open():  # a damaged archive is reported, not extended
                        pass
                    shutil.copyfile(self.path, temporary)
                with h5py.File(temporary, "a") as f:
                    if FORMAT not in f.attrs.get("format", ""):
                        f.attrs["format"] = FORMAT
                        f.attrs["format_version"] = FORMAT_VERSION
                        f.attrs["description"] = "plateimpact study archive; see docs/archive.md"
                    group = self._study_group(f, study, constants or {})
                    runs = group.require_group("runs")
                    name, k = variant.name, 1
                    while name in runs:
                        k += 1
                        name = f"{variant.name}.{k}"
                    self._write_run(runs.create_group(name), result, attributes)
                with open(temporary, "rb+") as handle:
                    os.fsync(handle.fileno())
                os.replace(temporary, self.path)
                fsync_directory(self.path.parent)
            finally:
                temporary.unlink(missing_ok=True)
        return f"{study.name}/{name}"

    def finished_runs(self, study: StudyDefinition) -> dict[str, str]:
        """The runs of ``study`` already in the archive, by variant name: those whose
        recorded variant (plug-ins and settings) is one of the study's, on the same
        scenes. Empty when the archive or the study is not there yet."""
        if not self.path.exists():
            return {}
        with self._open() as f:
            if study.name not in f:
                return {}
            self._check_same_scenes(f[study.name], study)
            runs = f[study.name].get("runs", {})
            found: dict[str, str] = {}
            for name in sorted(runs, key=lambda r: _start(runs[r])):
                recorded = Variant.from_json(str(self._check_seal(runs[name])["variant"]))
                if recorded in study.variants and recorded.name not in found:
                    found[recorded.name] = f"{study.name}/{name}"
            return found

    @staticmethod
    def _check_same_scenes(group: h5py.Group, study: StudyDefinition) -> None:
        scenes, names = group["scenes"], set(study.scenes.columns)
        same = set(scenes) - {"plate_label"} == names and all(
            np.array_equal(scenes[k][()], study.scenes.columns[k]) for k in names
        )
        if not same:
            raise ArchiveError(
                f"the archive already holds a different study named {study.name!r}; "
                "rename the study"
            )

    def _remove_stale_copies(self) -> None:
        """Delete the temporary copies left by writers killed mid-append: we hold the
        lock, so no other writer is using one."""
        for copy in self.path.parent.glob(f".{self.path.name}.*.tmp"):
            copy.unlink(missing_ok=True)

    @staticmethod
    def _study_group(
        f: h5py.File, study: StudyDefinition, constants: dict[str, Parameter]
    ) -> h5py.Group:
        if study.name in f:
            group = f[study.name]
            Archive._check_same_scenes(group, study)
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

    @staticmethod
    def _write_run(group: h5py.Group, result: BatchResult, attributes: dict[str, object]) -> None:
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
            write_ragged(
                group.create_group("trajectory"), result.trajectory, "count", "time", fields
            )

    # -- reading ---------------------------------------------------------------------

    @contextlib.contextmanager
    def _open(self) -> Iterator[h5py.File]:
        check_not_busy(self.path, self.lock_path)
        if not self.path.exists():
            raise ArchiveError(f"archive {self.path} does not exist")
        if not h5py.is_hdf5(self.path):
            raise ArchiveError(f"{self.path} is not an HDF5 file")
        try:
            f = h5py.File(self.path, "r")
        except OSError as exc:
            raise ArchiveError(
                f"archive {self.path} cannot be opened: {_first_line(exc)}"
            ) from None
        with f:
            try:
                if f.attrs.get("format") != FORMAT:
                    raise ArchiveError(f"{self.path} is an HDF5 file but not a plateimpact archive")
                yield f
            except PlateImpactError:
                raise
            except (OSError, RuntimeError, KeyError, ValueError, TypeError) as exc:
                # Damaged structure (not just damaged data, which the checksums catch):
                # h5py raises any of these from a corrupt header, link or attribute.
                raise ArchiveError(f"archive {self.path} is damaged: {_first_line(exc)}") from None

    def _read(self, f: h5py.File, path: str) -> np.ndarray:
        try:
            return np.asarray(f[path][()])
        except (OSError, KeyError, ValueError) as exc:
            raise ArchiveError(
                f"archive {self.path}: {path} cannot be read ({_first_line(exc)}); "
                "the file is damaged"
            ) from None

    def _read_ragged(
        self, f: h5py.File, path: str, counts: str, per_row: Sequence[str], first: Sequence[str]
    ) -> Ragged:
        """A ragged array, its columns in the order ``first`` names them, then the rest."""
        stored = [k for k in f[path] if k != counts]
        names = [k for k in first if k in stored] + [k for k in stored if k not in first]
        values = {k: self._read(f, f"{path}/{k}") for k in names if k not in per_row}
        rows = {k: self._read(f, f"{path}/{k}") for k in names if k in per_row}
        try:
            return Ragged(self._read(f, f"{path}/{counts}"), values, rows)
        except ValueError as exc:
            raise ArchiveError(f"archive {self.path}: {path} is damaged ({exc})") from None

    def studies(self) -> list[str]:
        with self._open() as f:
            return list(f)

    def runs(self) -> list[str]:
        """Every run as ``STUDY/RUN``, in the order written."""
        with self._open() as f:
            return [
                f"{study}/{run}"
                for study in f
                for run in sorted(
                    f[study].get("runs", {}), key=lambda r: _start(f[study]["runs"][r])
                )
            ]

    def resolve(self, run: str) -> str:
        """``STUDY/RUN`` for a run named either way; UnknownNameError lists the runs."""
        runs = self.runs()
        if run in runs:
            return run
        matches = [r for r in runs if r.split("/", 1)[1] == run]
        if len(matches) == 1:
            return matches[0]
        hint = "ambiguous; " if matches else ""
        raise UnknownNameError(f"no run {run!r} in {self.path} ({hint}runs: {', '.join(runs)})")

    def study(self, name: str | None = None) -> ArchivedStudy:
        """The study as it was defined (scenes, variants, labels, description)."""
        with self._open() as f:
            name = self._study_name(f, name)
            group = f[name]
            self._check_seal(group)
            columns = {
                k: self._read(f, f"{name}/scenes/{k}")
                for k in group["scenes"]
                if k != "plate_label"
            }
            labels = json.loads(group.attrs["plate_labels"])
            index = self._read(f, f"{name}/scenes/plate_label")
            variants = tuple(Variant(**v) for v in json.loads(group.attrs["variants"]))
            return ArchivedStudy(
                name,
                SceneBatch(columns),
                variants,
                tuple(labels[i] for i in index),
                str(group.attrs["description"]),
            )

    def _study_name(self, f: h5py.File, name: str | None) -> str:
        if name is None:
            if len(f) != 1:
                raise UnknownNameError(f"{self.path} holds studies {', '.join(f)}: name one")
            return str(next(iter(f)))
        if name not in f:
            raise UnknownNameError(f"no study {name!r} in {self.path}; studies: {', '.join(f)}")
        return name

    def metadata(self, run: str) -> dict[str, object]:
        run = self.resolve(run)
        with self._open() as f:
            attributes = self._check_seal(f[_run_path(run)])
        out: dict[str, object] = {}
        for key, value in attributes.items():
            if key in ("variant", "model", "versions", "failure_state_units"):
                value = json.loads(str(value))
            out[key] = value
        return out

    def _check_seal(self, group: h5py.Group) -> dict[str, object]:
        """The group's attributes, after checking them against their digest (attributes
        have no fletcher32 checksum of their own)."""
        attributes = plain_attributes(group)
        sealed = attributes.pop(SEAL, None)
        if sealed is not None and sealed != digest(attributes):
            raise ArchiveError(
                f"archive {self.path}: the attributes of {group.name} are damaged "
                "(their digest does not match)"
            )
        return attributes

    def results(self, run: str) -> BatchResult:
        """The run's results, bit for bit as they were computed."""
        run = self.resolve(run)
        base = _run_path(run)
        with self._open() as f:
            columns = {k: self._read(f, f"{base}/results/{k}") for k in RESULT_FIELDS}
            craters = trajectory = None
            if "crater" in f[base]:
                path = f"{base}/crater"
                craters = self._read_ragged(
                    f, path, "counts", ["impact_point"], list(CRATER_FIELDS)
                )
            if "trajectory" in f[base]:
                path = f"{base}/trajectory"
                trajectory = self._read_ragged(f, path, "count", [], list(TRAJECTORY_FIELDS))
            return BatchResult(columns, trajectory, craters=craters)


def _run_path(run: str) -> str:
    study, name = run.split("/", 1)
    return f"{study}/runs/{name}"


def _start(group: h5py.Group) -> str:
    return str(group.attrs.get("start_time", ""))


def _first_line(exc: BaseException) -> str:
    text = str(exc).strip().splitlines()
    return text[0] if text else type(exc).__name__
