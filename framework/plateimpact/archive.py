"""HDF5 archives of study runs (schema: docs/archive.md).

One file holds any number of studies; each study holds its scenes once and any number
of runs. A run is appended by copying the archive to a temporary file, adding the run
there and renaming the copy over the original (``os.replace``), so a crash at any point
leaves the previous archive, with every finished run, untouched. A lock file next to
the archive names the writing process; while it lives, opening the archive is refused.
"""

from __future__ import annotations

import contextlib
import datetime as dt
import hashlib
import json
import os
import platform
import shutil
import socket
import subprocess
import time
from collections.abc import Iterator
from importlib import metadata as importlib_metadata
from pathlib import Path

import h5py
import numpy as np

from .batch import BASE_COLUMNS, SceneBatch
from .crater import CraterSections
from .errors import ArchiveError, PlateImpactError, UnknownNameError
from .results import RESULT_FIELDS, TRAJECTORY_FIELDS, BatchResult
from .simulation import Simulation
from .study import Study, StudyResults, Variant

FORMAT, FORMAT_VERSION = "plateimpact-archive", 1

SCENE_UNITS = {
    "radius": ("m", "sphere radius Rs"),
    "mass": ("kg", "sphere mass m"),
    "thickness": ("m", "plate thickness T"),
    "a": ("Pa", "Poncelet strength term a"),
    "b": ("kg/m^3", "Poncelet inertia term b"),
    "critical_penetration": ("m", "critical penetration P* of the plate"),
    "failure_angle": ("rad", "failure angle alpha* on the sphere"),
    "impact_speed": ("m/s", "impact speed Vs"),
    "impact_obliquity": ("rad", "impact obliquity theta_s from the plate normal"),
}
RESULT_DESCRIPTIONS = {
    "outcome": "1 ricochet, 2 embedment, 3 perforation",
    "exit_speed": "speed when contact ends (0 for embedment)",
    "exit_obliquity": "direction from the plate normal when contact ends or at rest",
    "contact_time": "time from first contact to the outcome",
    "max_penetration": "largest penetration P reached",
    "plate_failed": "whether the plate failed (P reached the onset penetration)",
    "failure_time": "time of plate failure (NaN: none)",
    "failure_penetration": "penetration at plate failure (NaN: none)",
    "failure_lateral": "lateral displacement at plate failure (NaN: none)",
}
TRAJECTORY_DESCRIPTIONS = {
    "time": "time since first contact",
    "penetration": "depth P of the sphere's deepest point below the front surface",
    "lateral": "lateral displacement Y of the sphere's centre",
    "obliquity": "direction theta of the velocity from the plate normal",
    "speed": "speed V",
}
#: The crater group: a contiguous ragged array like the trajectories.
CRATER_DESCRIPTIONS = {
    "lateral": ("m", "distance along the plate from the crater's entry point (all scenes)"),
    "depth": ("m", "depth of the crater floor below the front surface (all scenes)"),
    "counts": ("1", "points per scene's section, in scene order"),
    "impact_point": ("m", "lateral position of first contact in the section's coordinates"),
}
assert set(SCENE_UNITS) == set(BASE_COLUMNS) and set(RESULT_DESCRIPTIONS) == set(RESULT_FIELDS)


def _dataset(group: h5py.Group, name: str, data: np.ndarray, units: str, description: str) -> None:
    """A chunked, fletcher32-checksummed 1-D dataset with ``units`` and ``description``."""
    data = np.asarray(data)
    chunk = (int(min(max(data.size, 1), 1 << 16)),)
    ds = group.create_dataset(name, data=data, chunks=chunk, maxshape=(None,), fletcher32=True)
    ds.attrs["units"] = units
    ds.attrs["description"] = description


#: Attribute holding the SHA-256 of a study's or run's other attributes.
SEAL = "attributes_sha256"


def _plain_attributes(group: h5py.Group) -> dict[str, object]:
    return {k: v.item() if isinstance(v, np.generic) else v for k, v in group.attrs.items()}


def _digest(attributes: dict[str, object]) -> str:
    text = json.dumps({k: attributes[k] for k in sorted(attributes)}, sort_keys=True)
    return hashlib.sha256(text.encode()).hexdigest()


def _seal(group: h5py.Group) -> None:
    """Store the digest of the group's attributes (checked on reading)."""
    attributes = _plain_attributes(group)
    attributes.pop(SEAL, None)
    group.attrs[SEAL] = _digest(attributes)


def _write_craters(group: h5py.Group, craters: CraterSections) -> None:
    group.attrs["layout"] = (
        "contiguous ragged array (CF): counts gives each scene's points (eqs 31-39)"
    )
    for name, (units, description) in CRATER_DESCRIPTIONS.items():
        _dataset(group, name, getattr(craters, name), units, description)
    group["counts"].attrs["sample_dimension"] = "lateral"


def _git_commit() -> str:
    """The git commit of the package's source tree, if it is a checkout ("unknown" if not)."""
    here = Path(__file__).resolve().parent
    try:
        out = subprocess.run(
            ["git", "-C", str(here), "rev-parse", "HEAD"],
            capture_output=True,
            text=True,
            timeout=5,
            check=True,
        )
        return out.stdout.strip()
    except (OSError, subprocess.SubprocessError):
        return "unknown"


def _versions() -> dict[str, str]:
    versions = {"python": platform.python_version()}
    for package in ("plateimpact", "numpy", "scipy", "attrs", "pluggy", "h5py"):
        try:
            versions[package] = importlib_metadata.version(package)
        except importlib_metadata.PackageNotFoundError:
            versions[package] = "unknown"
    return versions


class RunMetadata:
    """What an archive records about a run besides its numbers (docs/archive.md)."""

    def __init__(self, variant: Variant, simulation: Simulation) -> None:
        self.variant = variant
        self.model = simulation.describe()
        self.state_names = simulation.model.failure.state_names
        self.state_units = getattr(simulation.model.failure, "state_units", ())
        self.start = dt.datetime.now(dt.UTC)
        self._clock = time.perf_counter()
        self.end = self.start
        self.wall_time = 0.0

    def finish(self) -> None:
        self.end = dt.datetime.now(dt.UTC)
        self.wall_time = time.perf_counter() - self._clock

    def as_attributes(self) -> dict[str, object]:
        return {
            "variant": self.variant.to_json(),
            "model": json.dumps(self.model, sort_keys=True),
            "versions": json.dumps(_versions(), sort_keys=True),
            "git_commit": _git_commit(),
            "host": socket.gethostname(),
            "start_time": self.start.isoformat(),
            "end_time": self.end.isoformat(),
            "wall_time_s": self.wall_time,
            "failure_state_units": json.dumps(
                dict(zip(self.state_names, self.state_units, strict=False))
            ),
        }


def _pid_alive(pid: int) -> bool:
    try:
        os.kill(pid, 0)
    except ProcessLookupError:
        return False
    except PermissionError:
        return True
    return True


class Archive:
    """An HDF5 archive of studies and their runs at ``path``.

    Runs are named ``STUDY/RUN``; the bare ``RUN`` is enough when one study has it.
    Every failure to open or read (missing directory, not HDF5, checksum mismatch, a
    live writer) raises :class:`ArchiveError` with a one-line message.
    """

    def __init__(self, path: str | os.PathLike) -> None:
        self.path = Path(path)
        self.lock_path = self.path.with_name(self.path.name + ".lock")

    # -- writing ---------------------------------------------------------------------

    def check_writable(self) -> None:
        """Refuse early what :meth:`append_run` would refuse after a long run."""
        if not self.path.parent.is_dir():
            raise ArchiveError(f"archive {self.path}: directory {self.path.parent} does not exist")
        self._check_not_busy()
        if self.path.exists():
            with self._open():
                pass

    @contextlib.contextmanager
    def _lock(self) -> Iterator[None]:
        for _ in range(2):
            try:
                fd = os.open(self.lock_path, os.O_CREAT | os.O_EXCL | os.O_WRONLY, 0o644)
            except FileExistsError:
                self._check_not_busy()  # raises if the writer lives; else the lock is stale
                self.lock_path.unlink(missing_ok=True)
                continue
            with os.fdopen(fd, "w") as handle:
                handle.write(f"{os.getpid()} {socket.gethostname()}\n")
            break
        else:
            raise ArchiveError(f"archive {self.path}: cannot take the lock {self.lock_path}")
        try:
            yield
        finally:
            self.lock_path.unlink(missing_ok=True)

    def _check_not_busy(self) -> None:
        try:
            pid_text, host = self.lock_path.read_text().split()[:2]
            pid = int(pid_text)
        except (OSError, ValueError):
            return
        if pid != os.getpid() and (host != socket.gethostname() or _pid_alive(pid)):
            raise ArchiveError(
                f"archive {self.path} is being written by process {pid} on {host}; "
                f"wait for it to finish (or remove {self.lock_path} if that process is gone)"
            )

    def append_run(
        self, study: Study, variant: Variant, result: BatchResult, attributes: dict[str, object]
    ) -> str:
        """Add one finished run of ``study`` (atomically); returns its name ``STUDY/RUN``."""
        if not self.path.parent.is_dir():
            raise ArchiveError(f"archive {self.path}: directory {self.path.parent} does not exist")
        with self._lock():
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
                    group = self._study_group(f, study)
                    runs = group.require_group("runs")
                    name, k = variant.name, 1
                    while name in runs:
                        k += 1
                        name = f"{variant.name}.{k}"
                    self._write_run(runs.create_group(name), result, attributes)
                with open(temporary, "rb+") as handle:
                    os.fsync(handle.fileno())
                os.replace(temporary, self.path)
                _fsync_directory(self.path.parent)
            finally:
                temporary.unlink(missing_ok=True)
        return f"{study.name}/{name}"

    def finished_runs(self, study: Study) -> dict[str, str]:
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
    def _check_same_scenes(group: h5py.Group, study: Study) -> None:
        scenes = group["scenes"]
        same = set(scenes) >= set(BASE_COLUMNS) and all(
            np.array_equal(scenes[k][()], getattr(study.scenes, k)) for k in BASE_COLUMNS
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
    def _study_group(f: h5py.File, study: Study) -> h5py.Group:
        if study.name in f:
            group = f[study.name]
            Archive._check_same_scenes(group, study)
            return group
        group = f.create_group(study.name)
        group.attrs["description"] = study.description
        group.attrs["variants"] = json.dumps([json.loads(v.to_json()) for v in study.variants])
        labels = sorted(set(study.plate_labels))
        group.attrs["plate_labels"] = json.dumps(labels)
        _seal(group)
        scenes = group.create_group("scenes")
        scenes.attrs["count"] = study.scenes.size
        for name, (units, description) in SCENE_UNITS.items():
            _dataset(scenes, name, getattr(study.scenes, name), units, description)
        index = np.array([labels.index(label) for label in study.plate_labels], dtype=np.int32)
        _dataset(scenes, "plate_label", index, "1", "index into the study's plate_labels attribute")
        return group

    @staticmethod
    def _write_run(group: h5py.Group, result: BatchResult, attributes: dict[str, object]) -> None:
        for key, value in attributes.items():
            group.attrs[key] = value
        _seal(group)
        results = group.create_group("results")
        for name, units in RESULT_FIELDS.items():
            _dataset(results, name, result.columns[name], units or "1", RESULT_DESCRIPTIONS[name])
        if result.craters is not None:
            _write_craters(group.create_group("crater"), result.craters)
        if result.trajectory is None:
            return
        state_units = json.loads(str(attributes.get("failure_state_units", "{}")))
        trajectory = group.create_group("trajectory")
        trajectory.attrs["layout"] = (
            "contiguous ragged array (CF): count gives each scene's samples"
        )
        _dataset(
            trajectory, "count", result.trajectory_counts, "1", "samples per scene, in scene order"
        )
        trajectory["count"].attrs["sample_dimension"] = "time"
        for name, values in result.trajectory.items():
            if name in TRAJECTORY_FIELDS:
                units, description = TRAJECTORY_FIELDS[name], TRAJECTORY_DESCRIPTIONS[name]
            else:
                state = name.removeprefix("failure_")
                units = state_units.get(state, "1")
                description = f"failure-model state {state!r} (NaN before failure)"
            _dataset(trajectory, name, values, units, description)

    # -- reading ---------------------------------------------------------------------

    @contextlib.contextmanager
    def _open(self) -> Iterator[h5py.File]:
        self._check_not_busy()
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
            return f[path][()]
        except (OSError, KeyError, ValueError) as exc:
            raise ArchiveError(
                f"archive {self.path}: {path} cannot be read ({_first_line(exc)}); "
                "the file is damaged"
            ) from None

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

    def study(self, name: str | None = None) -> Study:
        """The study as it was defined (scenes, variants, labels, description)."""
        with self._open() as f:
            name = self._study_name(f, name)
            group = f[name]
            self._check_seal(group)
            columns = {k: self._read(f, f"{name}/scenes/{k}") for k in BASE_COLUMNS}
            labels = json.loads(group.attrs["plate_labels"])
            index = self._read(f, f"{name}/scenes/plate_label")
            variants = [Variant(**v) for v in json.loads(group.attrs["variants"])]
            return Study(
                name,
                SceneBatch(columns),
                variants,
                [labels[i] for i in index],
                str(group.attrs["description"]),
            )

    def _study_name(self, f: h5py.File, name: str | None) -> str:
        if name is None:
            if len(f) != 1:
                raise UnknownNameError(f"{self.path} holds studies {', '.join(f)}: name one")
            return next(iter(f))
        if name not in f:
            raise UnknownNameError(f"no study {name!r} in {self.path}; studies: {', '.join(f)}")
        return name

    def metadata(self, run: str) -> dict[str, object]:
        run = self.resolve(run)
        with self._open() as f:
            attrs = self._check_seal(f[_run_path(run)])
        out: dict[str, object] = {}
        for key, value in attrs.items():
            if key in ("variant", "model", "versions", "failure_state_units"):
                value = json.loads(value)
            out[key] = value
        return out

    def _check_seal(self, group: h5py.Group) -> dict[str, object]:
        """The group's attributes, after checking them against their digest (attributes
        have no fletcher32 checksum of their own)."""
        attrs = _plain_attributes(group)
        sealed = attrs.pop(SEAL, None)
        if sealed is not None and sealed != _digest(attrs):
            raise ArchiveError(
                f"archive {self.path}: the attributes of {group.name} are damaged "
                "(their digest does not match)"
            )
        return attrs

    def results(self, run: str) -> BatchResult:
        """The run's results, bit for bit as they were computed."""
        run = self.resolve(run)
        base = _run_path(run)
        with self._open() as f:
            columns = {k: self._read(f, f"{base}/results/{k}") for k in RESULT_FIELDS}
            craters = None
            if "crater" in f[base]:
                craters = CraterSections(
                    **{k: self._read(f, f"{base}/crater/{k}") for k in CRATER_DESCRIPTIONS}
                )
            if "trajectory" not in f[base]:
                return BatchResult(columns, craters=craters)
            names = [k for k in f[f"{base}/trajectory"] if k != "count"]
            order = [k for k in TRAJECTORY_FIELDS if k in names] + [
                k for k in names if k not in TRAJECTORY_FIELDS
            ]
            trajectory = {k: self._read(f, f"{base}/trajectory/{k}") for k in order}
            counts = self._read(f, f"{base}/trajectory/count")
            return BatchResult(columns, trajectory, counts, craters=craters)

    def load(self, study: str | None = None) -> StudyResults:
        """The study and all its runs."""
        definition = self.study(study)
        runs = {
            r.split("/", 1)[1]: self.results(r)
            for r in self.runs()
            if r.split("/", 1)[0] == definition.name
        }
        return StudyResults(definition, runs)


def _run_path(run: str) -> str:
    study, name = run.split("/", 1)
    return f"{study}/runs/{name}"


def _start(group: h5py.Group) -> str:
    return str(group.attrs.get("start_time", ""))


def _first_line(exc: BaseException) -> str:
    text = str(exc).strip().splitlines()
    return text[0] if text else type(exc).__name__


def _fsync_directory(directory: Path) -> None:
    with contextlib.suppress(OSError):
        fd = os.open(directory, os.O_RDONLY)
        try:
            os.fsync(fd)
        finally:
            os.close(fd)
