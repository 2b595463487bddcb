"""HDF5 archives of study runs (schema: docs/archive.md).

One file holds any number of studies; each study holds its scenes once and any number
of runs. A run is appended by copying the archive to a temporary file, adding the run
there and renaming the copy over the original (``os.replace``), so a crash at any point
leaves the previous archive, with every finished run, untouched (storage.append). One
writer at a time per real file, across threads and processes (storage.lock); readers
never wait, since the file they open is always a whole one. A symlinked archive is
followed: its target is written and locked, and keeps its mode, owner and group.
Stored limits and maps (storage.records, under ``/limits``) are appended the same way.
"""

from __future__ import annotations

import contextlib
import datetime as dt
import json
import os
import stat
from collections.abc import Callable, Iterator, Sequence
from pathlib import Path

import attrs
import h5py
import numpy as np

from ..batch import SceneBatch
from ..errors import ArchiveError, PlateImpactError, UnknownNameError
from ..parameters import Parameter
from ..ragged import Ragged
from ..results import CRATER_FIELDS, RESULT_FIELDS, TRAJECTORY_FIELDS, BatchResult
from ..variant import Variant
from . import append as append_module
from . import records
from .append import FORMAT, FORMAT_VERSION, StudyDefinition, append, check_same_scenes
from .hdf5 import SEAL, digest, plain_attributes
from .lock import ArchiveBusyError, locked
from .records import LIMITS, Record

#: How long a writer waits for another one to finish with the archive [s].
WAIT = 300.0


@attrs.frozen(eq=False)
class ArchivedStudy:
    """A study as an archive holds it: its name, scenes [SI], variants, one plate label
    per scene and description (``plateimpact.Study.from_archive`` makes it a Study)."""

    name: str
    scenes: SceneBatch
    variants: tuple[Variant, ...]
    plate_labels: tuple[str, ...]
    description: str


class Archive:
    """An HDF5 archive of studies and their runs at ``path``.

    Runs are named ``STUDY/RUN``; the bare ``RUN`` is enough when one study has it.
    Every failure to open, read or write (missing directory, not HDF5, another format
    version, checksum mismatch, read-only, busy) raises :class:`ArchiveError` with a
    one-line message. ``wait``: how long an append waits for another writer [s].
    """

    def __init__(self, path: str | os.PathLike[str], *, wait: float = WAIT) -> None:
        self.path = Path(path)
        self.named = bool(os.fspath(path))  # Path("") is Path("."): keep what was given
        self.real = Path(os.path.realpath(path)) if self.named else self.path
        # (a name-less path, "" or "/", is refused by every method before the lock is used)
        self.lock_path = self.real.parent / f"{self.real.name or 'root'}.lock"
        self.wait = wait

    # -- writing ---------------------------------------------------------------------

    def check_writable(self, study: str | None = None) -> None:
        """Refuse early what :meth:`append_run` would refuse after a long run: a missing
        or unwritable directory, a target that is not a regular file, a read-only
        archive, one that is damaged or of another format version, a ``study`` named as
        the stored limits' group."""
        directory = self.real.parent
        if not self.named or self.real.is_dir():
            raise ArchiveError(f"archive {self.path!s}: give an archive file name")
        if not directory.is_dir():
            raise ArchiveError(f"archive {self.path}: directory {directory} does not exist")
        if not os.access(directory, os.W_OK | os.X_OK):
            raise ArchiveError(f"archive {self.path}: directory {directory} is not writable")
        if study is not None:
            records.check_study_name(study, self.path)
        if self.real.exists():
            mode = os.stat(self.real).st_mode
            if not stat.S_ISREG(mode):
                raise ArchiveError(f"archive {self.path} is not a regular file")
            if not mode & (stat.S_IWUSR | stat.S_IWGRP | stat.S_IWOTH):
                raise ArchiveError(f"archive {self.path} is read-only; refusing to append to it")
            with self._open():  # damaged, not an archive, another version: refused now
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
        (units and descriptions of the scene datasets). If another writer keeps the
        archive longer than ``wait``, the run is saved to a side archive beside it and
        :class:`ArchiveBusyError` says where: a finished run is never lost."""
        self.check_writable(study.name)
        run = self._append(
            lambda real: append(real, study, variant, result, attributes, constants or {}),
            lambda name: f"run {study.name}/{name}",
            variant.name,
            f"{study.name}.{variant.name}",
        )
        return f"{study.name}/{run}"

    def append_record(self, name: str, record: Record) -> str:
        """Add ``record`` (limits or a map, as plain data) as ``/limits/NAME``, or
        ``NAME.2``, ... (atomically, as runs are added); returns the name it took."""
        name = records.check_record_name(name)
        self.check_writable()
        return self._append(
            lambda real: records.append_record(real, name, record, self.path),
            lambda stored: f"{LIMITS}/{stored}",
            name,
            f"{LIMITS}.{name}",
        )

    def _append(
        self, add: Callable[[Path], str], label: Callable[[str], str], name: str, side_tag: str
    ) -> str:
        """Run ``add(real file)`` under the archive's lock; returns the name it stored.
        ``label(name)`` names what is added in messages; busy, it goes to a side archive
        ``STEM.SIDE_TAG.TIME.SUFFIX`` beside the real one."""
        stored = None
        try:
            with locked(self.path, self.real, self.lock_path, self.wait):
                self.check_writable()  # as it is now that we hold it
                stored = add(self.real)
                append_module.fault_point("unlock")
        except ArchiveBusyError as exc:
            side = self.real.with_name(
                f"{self.real.stem}.{side_tag}.{dt.datetime.now(dt.UTC):%Y%m%dT%H%M%S%f}"
                f"{self.real.suffix}"
            )
            add(side)
            raise ArchiveBusyError(f"{exc}; {label(name)} saved to {side}") from None
        except ArchiveError:
            raise
        except OSError as exc:
            if stored is not None:  # failed letting go of the lock: it is in
                raise ArchiveError(
                    f"archive {self.path}: {label(stored)} was added, then letting go "
                    f"of the lock failed: {exc.strerror or exc}"
                ) from None
            # a full disk, a lost mount: the archive is as it was
            raise ArchiveError(
                f"archive {self.path}: cannot add {label(name)}: "
                f"{exc.strerror or exc} (the archive is unchanged)"
            ) from None
        return stored

    def finished_runs(self, study: StudyDefinition) -> dict[str, str]:
        """The runs of ``study`` already in the archive, by variant name: those whose
        recorded variant (plug-ins and settings) is one of the study's, on the same
        scenes. Empty when the archive or the study is not there yet."""
        if not self.real.exists():
            return {}
        with self._open() as f:
            if study.name not in records.study_names(f):
                return {}
            check_same_scenes(f[study.name], study, self.path)
            runs = f[study.name].get("runs", {})
            found: dict[str, str] = {}
            for name in sorted(runs, key=lambda r: _start(runs[r])):
                recorded = Variant.from_json(str(self._check_seal(runs[name])["variant"]))
                if recorded in study.variants and recorded.name not in found:
                    found[recorded.name] = f"{study.name}/{name}"
            return found

    # -- reading ---------------------------------------------------------------------

    @contextlib.contextmanager
    def _open(self) -> Iterator[h5py.File]:
        if not self.named:
            raise ArchiveError("give an archive file name, got ''")
        if not self.real.exists():
            raise ArchiveError(f"archive {self.path} does not exist")
        if not self.real.is_file():
            raise ArchiveError(f"archive {self.path} is not a file")
        if not os.access(self.real, os.R_OK):
            raise ArchiveError(f"archive {self.path} cannot be read: permission denied")
        try:
            hdf5 = h5py.is_hdf5(self.real)
        except OSError as exc:
            raise ArchiveError(f"archive {self.path} cannot be read: {_first_line(exc)}") from None
        if not hdf5:
            raise ArchiveError(f"{self.path} is not an HDF5 file")
        try:
            f = h5py.File(self.real, "r")
        except OSError as exc:
            raise ArchiveError(
                f"archive {self.path} cannot be opened: {_first_line(exc)}"
            ) from None
        with f:
            try:
                if f.attrs.get("format") != FORMAT:
                    raise ArchiveError(f"{self.path} is an HDF5 file but not a plateimpact archive")
                version = f.attrs.get("format_version")
                if version != FORMAT_VERSION:
                    raise ArchiveError(
                        f"archive {self.path} has format version {version}; this plateimpact "
                        f"reads and writes version {FORMAT_VERSION}"
                    )
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
        except (OSError, KeyError, ValueError, MemoryError) as exc:  # memory: a damaged shape
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
            return records.study_names(f)

    def runs(self) -> list[str]:
        """Every run as ``STUDY/RUN``, in the order written."""
        with self._open() as f:
            return [
                f"{study}/{run}"
                for study in records.study_names(f)
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
        studies = records.study_names(f)
        if name is None:
            if len(studies) != 1:
                raise UnknownNameError(f"{self.path} holds studies {', '.join(studies)}: name one")
            return studies[0]
        if name not in studies:
            raise UnknownNameError(
                f"no study {name!r} in {self.path}; studies: {', '.join(studies)}"
            )
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
        if sealed is None:
            raise ArchiveError(
                f"archive {self.path}: the attributes of {group.name} are damaged "
                "(their digest is missing)"
            )
        if sealed != digest(attributes):
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

    # -- stored limits and maps ----------------------------------------------------------

    def limits_names(self) -> list[str]:
        """The stored limits and maps (records under ``/limits``), in the order written."""
        with self._open() as f:
            return records.record_names(f)

    def record(self, name: str) -> Record:
        """The stored record ``name`` (``NAME`` or ``limits/NAME``), its attributes checked
        against their digest; UnknownNameError lists the stored names."""
        with self._open() as f:
            names = records.record_names(f)
            if name not in names:
                name = name.removeprefix(f"{LIMITS}/")
            if name not in names:
                raise UnknownNameError(
                    f"no stored limits {name!r} in {self.path} "
                    f"(stored: {', '.join(names) or 'none'})"
                )
            self._check_seal(f[LIMITS])
            return records.read_record(
                f[f"{LIMITS}/{name}"], self._check_seal, lambda path: self._read(f, path)
            )


def _run_path(run: str) -> str:
    study, name = run.split("/", 1)
    return f"{study}/runs/{name}"


def _start(group: h5py.Group) -> str:
    return str(group.attrs.get("start_time", ""))


def _first_line(exc: BaseException) -> str:
    text = str(exc).strip().splitlines()
    return text[0] if text else type(exc).__name__
