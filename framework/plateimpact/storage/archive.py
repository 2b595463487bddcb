"""HDF5 archives of study runs (schema: docs/archive.md).

An archive is an index file (``ARCHIVE``, HDF5) that names its studies, runs and stored
limits, and a directory of data files beside it (``ARCHIVE.d``): one netCDF-4 file per
run, per study's scenes and per stored record, each written once and never changed, so
that xarray, h5py or any netCDF tool reads a run as it is. Appending writes the run's
file and then replaces the index atomically (storage.append), so a crash at any point
leaves the previous archive, with every finished run, untouched, and an append costs
the same whatever the number of runs already there. One writer at a time per real file,
across threads and processes (storage.lock); readers never wait, since the index they
open is always a whole one and names only complete data files. A symlinked archive is
followed: its target is written and locked, and keeps its mode, owner and group.
Format-1 archives (one file holding everything) are read; appends go to format 2.
"""

from __future__ import annotations

import os
from collections.abc import Callable
from pathlib import Path

import attrs
import h5py
import numpy as np

from ..base.errors import ArchiveError, ParameterError, PlateImpactError, UnknownNameError
from ..base.parameters import Parameter
from ..base.untrusted import printable
from ..model.batch import SceneBatch
from ..model.results import CRATER_FIELDS, RESULT_FIELDS, TRAJECTORY_FIELDS, BatchResult, Outcome
from ..run.variant import Variant
from . import append as append_module
from . import records
from . import stored_attributes as typed
from .append import (
    StudyDefinition,
    append,
    check_same_scenes,
)
from .confined import data_file_name
from .lock import ArchiveBusyError, locked
from .reader import ArchiveFiles
from .records import LIMITS, Record
from .writable import check_writable, side_archive

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


class Archive(ArchiveFiles):
    """An HDF5 archive of studies and their runs at ``path`` (its data files in
    ``PATH.d``).

    Runs are named ``STUDY/RUN``; the bare ``RUN`` is enough when one study has it.
    Every failure to open, read or write (missing directory, not HDF5, another format
    version, checksum mismatch, missing data file, read-only, busy) raises
    :class:`ArchiveError` with a one-line message. ``wait``: how long an append waits
    for another writer [s] (inf: as long as it takes).
    """

    def __init__(self, path: str | os.PathLike[str], *, wait: float = WAIT) -> None:
        super().__init__(path)
        if isinstance(wait, bool) or not isinstance(wait, int | float) or not wait >= 0.0:
            raise ParameterError(
                "wait", f"wait must be a number of seconds >= 0 (inf: no limit), got {wait!r}"
            )
        self.wait = float(wait)

    # -- writing ---------------------------------------------------------------------

    def check_writable(self, study: str | None = None) -> None:
        """Refuse early what :meth:`append_run` would refuse after a long run: a missing
        or unwritable directory (a read-only filesystem), names too long for the files
        the archive makes, a target that is not a regular file, a read-only archive, a
        data directory or lock that is a symlink or not what it should be, an archive
        that is damaged, of another format version or reaches outside itself (its
        links are checked, and a study's scenes opened), a ``study`` named as the
        stored limits' group."""
        check_writable(self, study)

    def append_run(
        self,
        study: StudyDefinition,
        variant: Variant,
        result: BatchResult,
        attributes: dict[str, object],
        constants: dict[str, Parameter] | None = None,
        *,
        run: str | None = None,
        overwrite: bool = False,
    ) -> str:
        """Add one finished run of ``study`` (atomically) as ``run`` (default: the
        variant's name); returns its name ``STUDY/RUN``. A run of that name is replaced
        with ``overwrite`` and otherwise refused (``RunExistsError``, an :class:`ArchiveError`).

        ``constants`` are the declarations of the plate constants the run's plug-ins read
        (units and descriptions of the scene columns). If another writer keeps the
        archive longer than ``wait``, the run is saved to a side archive beside it and
        ``ArchiveBusyError`` (an :class:`ArchiveError`) says where: a finished run is never lost."""
        self.check_writable(study.name)
        name = run or variant.name
        stored = self._append(
            lambda real: append(
                real, study, variant, result, attributes, constants or {}, name, overwrite
            ),
            lambda stored: f"run {study.name}/{stored}",
            name,
            f"{study.name}.{name}",
        )
        return f"{study.name}/{stored}"

    def append_record(self, name: str, record: Record, *, overwrite: bool = False) -> str:
        """Add ``record`` (limits or a map, as plain data) as ``/limits/NAME``, or
        ``NAME.2``, ... (with ``overwrite``: in the place of ``NAME``), atomically, as
        runs are added; returns the name it took."""
        name = records.check_record_name(name)
        self.check_writable()
        return self._append(
            lambda real: records.append_record(real, name, record, self.path, overwrite),
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
            side = side_archive(self.real, side_tag)
            with locked(side, side, side.with_name(f"{side.name}.lock"), 0.0):
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
            with self._linked(f, f"{study.name}/scenes") as scenes:
                check_same_scenes(scenes, study, self.path)
        found: dict[str, str] = {}
        for run in self.runs():
            if run.split("/", 1)[0] != study.name:
                continue
            recorded = self.recorded_variant(run)
            if recorded in study.variants and recorded.name not in found:
                found[recorded.name] = run
        return found

    # -- reading ---------------------------------------------------------------------

    def version(self) -> int:
        """The archive's format version."""
        with self._open() as f:
            return int(f.attrs["format_version"])

    def studies(self) -> list[str]:
        with self._open() as f:
            return records.study_names(f)

    def runs(self) -> list[str]:
        """Every run as ``STUDY/RUN``, in the order written."""
        with self._open() as f:
            if f.attrs["format_version"] != 1:  # links kept in the order made
                return [
                    f"{study}/{run}"
                    for study in records.study_names(f)
                    for run in f[study].get("runs", {})
                ]
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
        raise UnknownNameError(
            f"no run {printable(run)!r} in {self.path} ({hint}runs: {_listed(runs)})"
        )

    def data_file(self, run: str) -> Path | None:
        """The run's own netCDF file (format 2), which xarray opens as it is; None for a
        format-1 archive, whose runs live in the archive file itself."""
        study, name = self.resolve(run).split("/", 1)
        with self._open() as f:
            link = f.get(f"{study}/runs/{name}", getlink=True)
        if not isinstance(link, h5py.ExternalLink):
            return None
        return self.data / data_file_name(link.filename, f"archive {self.path}: run {run}")

    def study(self, name: str | None = None) -> ArchivedStudy:
        """The study as it was defined (scenes, variants, labels, description)."""
        with self._open() as f:
            name = self._study_name(f, name)
            what = f"archive {self.path}: study {printable(name)}"
            group = f[name]
            attributes = self._check_seal(group)
            labels = typed.plate_labels(attributes, what)
            variants = typed.study_variants(attributes, what)
            description = typed.text(attributes, "description", what)
            with self._linked(f, f"{name}/scenes") as scenes:
                size = self._scene_count(scenes)
                columns = {
                    k: self._read(scenes, k, "f", (size,))
                    for k in scenes
                    if k not in ("plate_label", "plate", "scene")
                }
                if "plate" in scenes:  # format 2: the label of each scene
                    text = self._read(scenes, "plate", "O", (size,))
                    if not all(isinstance(x, bytes | str) for x in text):
                        raise ArchiveError(f"{what}: its plate labels are not text")
                    per_scene = tuple(x.decode() if isinstance(x, bytes) else x for x in text)
                else:
                    index = self._read(scenes, "plate_label", "iu", (size,))
                    if size and not (0 <= index.min() and index.max() < len(labels)):
                        raise ArchiveError(f"{what}: a plate label index is out of range")
                    per_scene = tuple(labels[i] for i in index)
            try:
                batch = SceneBatch(columns)
            except PlateImpactError as exc:
                raise ArchiveError(
                    f"{what}: its scenes are not ones this plateimpact runs ({exc})"
                ) from None
            return ArchivedStudy(name, batch, variants, per_scene, description)

    def recorded_variant(self, run: str) -> Variant:
        """The variant (plug-ins and settings) the run ``STUDY/RUN`` records."""
        return typed.run_variant(
            self._attributes(run), f"archive {self.path}: run {printable(run)}"
        )

    def _study_name(self, f: h5py.File, name: str | None) -> str:
        studies = records.study_names(f)
        if name is None:
            if len(studies) != 1:
                raise UnknownNameError(f"{self.path} holds studies {_listed(studies)}: name one")
            return studies[0]
        if name not in studies:
            raise UnknownNameError(
                f"no study {printable(name)!r} in {self.path}; studies: {_listed(studies)}"
            )
        return name

    def _attributes(self, run: str) -> dict[str, object]:
        with self._open() as f, self._linked(f, _run_path(run)) as group:
            return self._check_seal(group)

    def raw_attributes(self, run: str) -> dict[str, object]:
        """The run's attributes as stored (JSON as text), their digest checked."""
        return self._attributes(self.resolve(run))

    def metadata(self, run: str) -> dict[str, object]:
        """What the run records of how it was made (variant, model, versions, commit,
        host, times), JSON decoded; the same keys in either format version."""
        run = self.resolve(run)
        return typed.run_metadata(
            self._attributes(run), f"archive {self.path}: run {printable(run)}"
        )

    def results(self, run: str) -> BatchResult:
        """The run's results, bit for bit as they were computed."""
        run = self.resolve(run)
        with self._open() as f:
            one = f.attrs["format_version"] == 1
            size = self._study_size(f, run.split("/", 1)[0])  # one result per scene
            with self._linked(f, _run_path(run)) as group:
                prefix = "results/" if one else ""
                columns = {
                    k: self._read(group, prefix + k, "iub" if k in CODES else "f", (size,))
                    for k in RESULT_FIELDS
                }
                for k, allowed in CODES.items():
                    if not np.isin(columns[k], allowed).all():
                        raise ArchiveError(
                            f"archive {self.path}: run {printable(run)}: {k} holds codes other "
                            f"than {', '.join(map(str, allowed))}; the file is damaged"
                        )
                columns["plate_failed"] = columns["plate_failed"].astype(bool)
                crater, path = ("crater/", "counts") if one else ("crater_", "count")
                craters = trajectory = None
                if crater + path in group:
                    craters = self._read_ragged(
                        group, crater, path, ["impact_point"], list(CRATER_FIELDS), size
                    )
                moves = "trajectory/" if one else "trajectory_"
                if moves + "count" in group:
                    trajectory = self._read_ragged(
                        group, moves, "count", [], list(TRAJECTORY_FIELDS), size
                    )
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
                    f"no stored limits {printable(name)!r} in {self.path} "
                    f"(stored: {_listed(names) or 'none'})"
                )
            self._check_seal(f[LIMITS])
            with self._linked(f, f"{LIMITS}/{name}") as group:
                return records.read_record(
                    group, self._check_seal, lambda path: self._read(group.file, path)
                )


#: Integer-coded results and the codes they may hold.
CODES = {"outcome": [int(o) for o in Outcome], "plate_failed": [0, 1]}


def _listed(names: list[str]) -> str:
    """Names from an archive (maybe someone else's) for a message: inert, and not
    endless."""
    return printable(", ".join(names), 400)


def _run_path(run: str) -> str:
    study, name = run.split("/", 1)
    return f"{study}/runs/{name}"


def _start(group: h5py.Group) -> str:
    return str(group.attrs.get("start_time", ""))
