"""Studies: a named set of scenes run through one or more model variants."""

from __future__ import annotations

import os
import warnings
from collections.abc import Iterable, Mapping, Sequence
from concurrent.futures import Executor
from pathlib import Path

import attrs
import numpy as np

from . import presets
from .batch import SceneBatch, check_chunk_size
from .bodies import Plate, Sphere
from .errors import ArchiveWaitWarning, ParameterError, UnknownNameError
from .progress import progress_bar
from .registry import PluginRegistry
from .results import BatchResult, Outcome
from .scene import Scene
from .simulation import DEFAULT_CHUNK_SIZE, run_chunk
from .storage.archive import Archive
from .storage.lock import ArchiveBusyError
from .storage.provenance import RunMetadata
from .variant import Variant, check_name


def _variants(value: Iterable[Variant] | Variant) -> tuple[Variant, ...]:
    given = (value,) if isinstance(value, Variant) else _tuple("variants", value)
    variants = tuple(v for v in given if isinstance(v, Variant))
    if len(variants) != len(given):
        wrong = next(v for v in given if not isinstance(v, Variant))
        raise ParameterError("variants", f"variants must be Variant objects, got {wrong!r:.80}")
    names = [v.name for v in variants]
    if not variants or len(set(names)) != len(names):
        raise ParameterError(
            "variants", f"variants must be one or more distinct names, got {names}"
        )
    return variants


def _plate_label(plate: Plate) -> str:
    """'MATERIAL/THICKNESS_MM', as preset names are spelled."""
    return f"{plate.material}/{plate.thickness * 1e3:g}"


def _tuple(name: str, value: Iterable[object]) -> tuple[object, ...]:
    """``value``'s items; a string or a non-iterable is a ParameterError naming it."""
    if isinstance(value, str | bytes):
        raise ParameterError(name, f"{name} must be a sequence, got the string {value!r}")
    try:
        return tuple(value)
    except TypeError:
        raise ParameterError(name, f"{name} must be a sequence, got {value!r:.80}") from None


def _labels(value: Sequence[str] | np.ndarray) -> tuple[str, ...]:
    return tuple(str(label) for label in _tuple("plate_labels", value))


def _scene_batch(instance: object, attribute: attrs.Attribute, value: object) -> None:
    if not isinstance(value, SceneBatch):
        raise ParameterError(
            "scenes",
            f"scenes must be a SceneBatch (see Study.grid, Study.from_scenes), got {value!r:.80}",
        )


@attrs.frozen(eq=False)
class Study:
    """A named set of scenes and the model variants to run on them.

    Parameters
    ----------
    name : str
        No '/': it names the study's group in an archive.
    scenes : SceneBatch
        The impacts, SI units (build with :meth:`grid` or :meth:`from_scenes`).
    variants : Variant or sequence of Variant
        Distinct names; each becomes one run.
    plate_labels : sequence of str
        One label per scene (the preset name for preset plates), for tables and plots.
    description : str
    """

    name: str = attrs.field(validator=check_name)
    scenes: SceneBatch = attrs.field(validator=_scene_batch)
    variants: tuple[Variant, ...] = attrs.field(converter=_variants)
    plate_labels: tuple[str, ...] = attrs.field(converter=_labels)
    description: str = ""

    @plate_labels.validator
    def _check_labels(self, attribute: attrs.Attribute, value: tuple[str, ...]) -> None:
        if len(value) != self.scenes.size:
            raise ParameterError(
                "plate_labels", f"plate_labels needs one label per scene ({self.scenes.size})"
            )

    @classmethod
    def grid(
        cls,
        name: str,
        plates: Sequence[str | Plate],
        obliquities_deg: Sequence[float],
        speeds: Sequence[float],
        variants: Iterable[Variant] | Variant,
        *,
        sphere: Sphere = presets.DEFAULT_SPHERE,
        description: str = "",
    ) -> Study:
        """Every plate × obliquity [deg] × speed [m/s]; plates by preset name or Plate."""
        batches, labels = [], []
        plates = _tuple("plates", plates)  # type: ignore[assignment]
        if not plates:
            raise ParameterError("plates", "a study grid needs one or more plates")
        for plate in plates:
            if not isinstance(plate, str | Plate):
                raise ParameterError(
                    "plates", f"plates must be preset names or Plate objects, got {plate!r}"
                )
            label = plate if isinstance(plate, str) else _plate_label(plate)
            plate = presets.plate(plate) if isinstance(plate, str) else plate
            batch = SceneBatch.grid(sphere, plate, speeds, np.radians(obliquities_deg))
            batches.append(batch)
            labels += [label] * batch.size
        return cls(name, SceneBatch.concat(batches), variants, labels, description)

    @classmethod
    def from_scenes(
        cls,
        name: str,
        scenes: Iterable[Scene],
        variants: Iterable[Variant] | Variant,
        *,
        description: str = "",
    ) -> Study:
        """An explicit list of scenes (custom plates and spheres)."""
        scenes = list(scenes)
        batch = SceneBatch.from_scenes(scenes)  # checks that they are scenes
        labels = [_plate_label(s.plate) for s in scenes]
        return cls(name, batch, variants, labels, description)

    @classmethod
    def from_archive(cls, path: str | os.PathLike[str], name: str | None = None) -> Study:
        """The study ``name`` (or the archive's only one) as it was defined."""
        record = Archive(path).study(name)
        return cls(
            record.name, record.scenes, record.variants, record.plate_labels, record.description
        )

    def variant(self, name: str) -> Variant:
        for variant in self.variants:
            if variant.name == name:
                return variant
        choices = ", ".join(v.name for v in self.variants)
        raise UnknownNameError(
            f"study {self.name!r} has no variant {name!r}; choose from: {choices}"
        )

    def run(
        self,
        *,
        archive: str | Path | Archive | None = None,
        executor: Executor | None = None,
        chunk_size: int = DEFAULT_CHUNK_SIZE,
        record_trajectory: bool = False,
        craters: bool = False,
        resume: bool = False,
        progress: bool | None = None,
        registry: PluginRegistry | None = None,
    ) -> StudyResults:
        """Run every variant on every scene.

        Parameters
        ----------
        archive : path or Archive, optional
            HDF5 archive to append each run to as soon as it finishes (docs/archive.md).
            ``Archive(path, wait=SECONDS)`` sets how long an append waits for another
            writer (default 300 s) before saving its run to a side archive.
        executor : concurrent.futures.Executor, optional
            Where chunks of ``chunk_size`` scenes run (a process pool, a Dask client's
            ``get_executor()``); the study stays the single writer of the archive.
        record_trajectory : bool
            Keep every scene's path.
        craters : bool
            Also compute every scene's crater section (eqs 31–39), which records the
            paths too; about 2 ms per scene.
        resume : bool
            Finish an interrupted study: a variant whose run is already in ``archive``
            (same plug-ins and settings, same scenes, with the trajectories or craters
            asked for) is read back instead of run again. Runs are archived only when
            finished, so an interrupted run is simply absent.
        progress : bool or None
            Progress bar on stderr, once the run has lasted 2 s; None shows it on a
            terminal only.
        """
        check_chunk_size(chunk_size)
        writer = archive if isinstance(archive, Archive) or archive is None else Archive(archive)
        if writer is not None:
            writer.check_writable(self.name)
        if resume and writer is None:
            raise ParameterError("resume", "resume=True needs the archive to resume from")
        finished = writer.finished_runs(self) if writer is not None and resume else {}
        simulations = {
            v.name: v.simulation(registry) for v in self.variants if v.name not in finished
        }
        constants = {}
        for simulation in simulations.values():  # a bad plate constant: refused before any run
            simulation.model.bind(self.scenes)
            constants.update(simulation.model.plate_constants())
        runs: dict[str, BatchResult] = {}
        with progress_bar(self.scenes.size * len(self.variants), self.name, progress) as bar:
            for variant in self.variants:
                if writer is not None and variant.name in finished:
                    kept = writer.results(finished[variant.name])
                    lacks = (craters and kept.craters is None) or (
                        record_trajectory and kept.trajectory is None
                    )
                    if not lacks:  # else run it again, keeping what was asked for
                        runs[variant.name] = kept
                        bar.update(self.scenes.size)
                        continue
                simulation = simulations.get(variant.name) or variant.simulation(registry)
                metadata = RunMetadata(variant, simulation)
                chunks = [
                    self.scenes.take(np.arange(lo, min(lo + chunk_size, self.scenes.size)))
                    for lo in range(0, self.scenes.size, chunk_size)
                ]
                parts = []
                if executor is None:
                    for chunk in chunks:
                        parts.append(run_chunk(simulation, chunk, record_trajectory, craters))
                        bar.update(chunk.size)
                else:
                    futures = [
                        executor.submit(run_chunk, simulation, chunk, record_trajectory, craters)
                        for chunk in chunks
                    ]
                    for future, chunk in zip(futures, chunks, strict=True):
                        parts.append(future.result())
                        bar.update(chunk.size)
                result = BatchResult.concat(parts)
                metadata.finish()
                runs[variant.name] = result
                if writer is not None:
                    try:
                        writer.append_run(
                            self, variant, result, metadata.as_attributes(), constants
                        )
                    except ArchiveBusyError as exc:  # the run was saved aside: say where
                        warnings.warn(str(exc), ArchiveWaitWarning, stacklevel=2)
        return StudyResults(self, runs)


@attrs.frozen(eq=False)
class Comparison:
    """Run B against run A on the same scenes: outcome changes and exit differences.

    ``exit_speed_change`` [m/s] and ``exit_obliquity_change`` [rad] are B − A, NaN where
    either run ends in embedment (no exit) for the obliquity.
    """

    run_a: str
    run_b: str
    outcome_a: np.ndarray
    outcome_b: np.ndarray
    exit_speed_change: np.ndarray
    exit_obliquity_change: np.ndarray

    @property
    def changed(self) -> np.ndarray:
        """Indices of the scenes whose outcome differs."""
        return np.flatnonzero(self.outcome_a != self.outcome_b)

    def summary(self) -> dict[str, object]:
        """Counts of each outcome transition and the largest exit differences (user units)."""
        transitions: dict[str, int] = {}
        for i in self.changed:
            key = f"{Outcome(self.outcome_a[i]).label} -> {Outcome(self.outcome_b[i]).label}"
            transitions[key] = transitions.get(key, 0) + 1
        both = np.isfinite(self.exit_obliquity_change)
        return {
            "scenes": int(self.outcome_a.size),
            "outcome_changes": int(self.changed.size),
            "transitions": transitions,
            "max_abs_exit_speed_change_m_s": float(
                np.max(np.abs(self.exit_speed_change), initial=0.0)
            ),
            "max_abs_exit_obliquity_change_deg": float(
                np.degrees(np.max(np.abs(self.exit_obliquity_change[both]), initial=0.0))
            ),
        }


class StudyResults:
    """The runs of a study, by name: each a :class:`BatchResult` over the study's scenes."""

    def __init__(self, study: Study, runs: Mapping[str, BatchResult]) -> None:
        self.study = study
        self.runs = dict(runs)

    @classmethod
    def from_archive(cls, path: str | os.PathLike[str], study: str | None = None) -> StudyResults:
        """A study (or the archive's only one) and all its runs, by run name."""
        archive = Archive(path)
        definition = Study.from_archive(path, study)
        runs = {
            r.split("/", 1)[1]: archive.results(r)
            for r in archive.runs()
            if r.split("/", 1)[0] == definition.name
        }
        return cls(definition, runs)

    def __getitem__(self, name: str) -> BatchResult:
        try:
            return self.runs[name]
        except KeyError:
            choices = ", ".join(self.runs)
            raise UnknownNameError(f"no run {name!r}; choose from: {choices}") from None

    def compare(self, run_a: str, run_b: str) -> Comparison:
        """Per scene: outcome A and B, Δ exit speed and Δ exit obliquity (B − A)."""
        a, b = self[run_a], self[run_b]
        flying = (a.outcome != Outcome.EMBEDMENT) & (b.outcome != Outcome.EMBEDMENT)
        return Comparison(
            run_a,
            run_b,
            a.outcome.copy(),
            b.outcome.copy(),
            b.exit_speed - a.exit_speed,
            np.where(flying, b.exit_obliquity - a.exit_obliquity, np.nan),
        )
