"""Studies: a named set of scenes run through one or more model variants."""

from __future__ import annotations

import os
import warnings
from collections.abc import Iterable, Mapping, Sequence
from concurrent.futures import Executor
from pathlib import Path
from typing import TYPE_CHECKING

import attrs
import numpy as np

from ..base.errors import ArchiveWaitWarning, ParameterError, UnknownNameError
from ..base.parameters import Parameter
from ..comparison.ranges import Comparison
from ..model import views
from ..model.batch import SceneBatch, check_chunk_size
from ..model.bodies import Plate, Sphere
from ..model.results import BatchResult
from ..model.scene import Scene
from ..model.tables import SceneInputs, scene_table
from ..provenance.metadata import RunMetadata
from ..registry.plugin_registry import PluginRegistry, default_registry
from ..run.progress import progress_bar
from ..run.simulation import DEFAULT_CHUNK_SIZE, run_in_chunks
from ..run.variant import Variant, check_name
from ..storage.archive import Archive
from ..storage.lock import ArchiveBusyError
from .reruns import plan_runs

if TYPE_CHECKING:
    import pandas
    import xarray


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
        sphere: Sphere | None = None,
        description: str = "",
        registry: PluginRegistry | None = None,
    ) -> Study:
        """Every plate × obliquity × speed: ``obliquities_deg`` [deg] (the name says so:
        :meth:`SceneBatch.grid` takes radians), ``speeds`` [m/s]; plates by preset name
        or Plate, presets and the default ``sphere`` from ``registry`` (default: the
        installed plug-in packages')."""
        registry = registry or default_registry()
        sphere = registry.sphere if sphere is None else sphere
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
            plate = registry.plate(plate) if isinstance(plate, str) else plate
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

    def check_archive(
        self,
        archive: str | Path | Archive,
        *,
        resume: bool = False,
        overwrite: bool = False,
        run_names: Mapping[str, str] | None = None,
        registry: PluginRegistry | None = None,
    ) -> None:
        """Refuse now what :meth:`run` into ``archive`` would refuse before running: an
        archive that cannot be written, a run name that is taken (without ``resume`` or
        ``overwrite``), a study of this name with other scenes, a run ``resume`` would
        keep that other code computed (``StaleRunError``)."""
        writer = archive if isinstance(archive, Archive) else Archive(archive)
        writer.check_writable(self.name)
        plan_runs(writer, self, run_names, resume, overwrite, registry)

    def run(
        self,
        *,
        archive: str | Path | Archive | None = None,
        executor: Executor | None = None,
        chunk_size: int = DEFAULT_CHUNK_SIZE,
        record_trajectory: bool = False,
        craters: bool = False,
        resume: bool = False,
        overwrite: bool = False,
        run_names: Mapping[str, str] | None = None,
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
            finished, so an interrupted run is simply absent. A stored run whose
            recorded code (each plug-in's distribution, version and source hash, and
            the core's) is not what the variant would run now, or that records none,
            is refused before anything runs (``StaleRunError``: replace it with
            ``overwrite`` or store the new run under another name).
        overwrite : bool
            Replace the stored runs of the study's variants (each atomically, when its
            new run is finished). Without ``resume`` or ``overwrite`` a run name that
            is taken is refused before anything runs (``RunExistsError``).
        run_names : mapping, optional
            Store a variant's run under another name (variant name -> run name).
        progress : bool or None
            Progress bar on stderr, once the run has lasted 2 s; None shows it on a
            terminal only.
        """
        check_chunk_size(chunk_size)
        writer = archive if isinstance(archive, Archive) or archive is None else Archive(archive)
        if writer is not None:
            writer.check_writable(self.name)
        planned = plan_runs(writer, self, run_names, resume, overwrite, registry)
        finished = {v: p.kept for v, p in planned.items() if p.kept is not None}
        simulations = {
            v.name: v.simulation(registry) for v in self.variants if v.name not in finished
        }
        constants = {}
        bound = {}  # each model bound once: a bad plate constant is refused before any run
        for name, simulation in simulations.items():
            bound[name] = simulation.model.bind(self.scenes)
            constants.update(simulation.model.plate_constants())
        runs: dict[str, BatchResult] = {}
        with progress_bar(self.scenes.size * len(self.variants), self.name, progress) as bar:
            for variant in self.variants:
                if writer is not None and variant.name in finished:
                    kept = writer.results(finished[variant.name])
                    lacks = (craters and kept.craters is None) or (
                        record_trajectory and kept.trajectory is None
                    )
                    if not lacks:  # else run it again (replacing it), keeping what was asked for
                        runs[variant.name] = kept
                        bar.update(self.scenes.size)
                        continue
                if variant.name not in simulations:  # kept, but lacking what was asked for
                    simulations[variant.name] = variant.simulation(registry)
                    bound[variant.name] = simulations[variant.name].model.bind(self.scenes)
                simulation = simulations[variant.name]
                metadata = RunMetadata(variant, simulation)
                result = run_in_chunks(
                    simulation, bound.pop(variant.name), chunk_size, executor,
                    record_trajectory, craters, bar.update,
                )  # fmt: skip
                metadata.finish()
                runs[variant.name] = result
                if writer is not None:
                    try:
                        plan = planned[variant.name]
                        # the run's plug-ins' declarations, else its registry's
                        declared = {**simulation.registry.plate_constants, **constants}
                        writer.append_run(
                            self, variant, result, metadata.as_attributes(), declared,
                            run=plan.run, overwrite=plan.replace or plan.kept is not None,
                        )  # fmt: skip
                    except ArchiveBusyError as exc:  # the run was saved aside: say where
                        warnings.warn(str(exc), ArchiveWaitWarning, stacklevel=2)
        # the plate constants' units for the results' tables: as the archive has them
        declarations: dict[str, Parameter] = {}
        for simulation in simulations.values():
            declarations.update(simulation.registry.plate_constants)
        return StudyResults(self, runs, constants={**declarations, **constants})


class StudyResults:
    """The runs of a study, by name: each a :class:`BatchResult` over the study's scenes,
    with them attached as its inputs (each scene's plate label too; ``constants``
    declares the plate constants' units)."""

    def __init__(
        self,
        study: Study,
        runs: Mapping[str, BatchResult],
        *,
        constants: Mapping[str, Parameter] | None = None,
    ) -> None:
        self.study = study
        self.runs = dict(runs)
        self.constants = dict(constants or {})
        for run in self.runs.values():
            if isinstance(study, Study) and len(run) == study.scenes.size:
                run.inputs = self.inputs

    @property
    def inputs(self) -> SceneInputs:
        """The study's scenes [SI], their plate constants' declarations and plate labels."""
        study = self.study
        return SceneInputs(study.scenes.columns, self.constants, study.plate_labels)

    @classmethod
    def from_archive(
        cls,
        path: str | os.PathLike[str],
        study: str | None = None,
        *,
        registry: PluginRegistry | None = None,
    ) -> StudyResults:
        """A study (or the archive's only one) and all its runs, by run name; the plate
        constants' units as ``registry`` declares them (None: unknown)."""
        archive = Archive(path)
        definition = Study.from_archive(path, study)
        runs = {
            r.split("/", 1)[1]: archive.results(r)
            for r in archive.runs()
            if r.split("/", 1)[0] == definition.name
        }
        constants = None if registry is None else registry.plate_constants
        return cls(definition, runs, constants=constants)

    def to_xarray(self, registry: PluginRegistry | None = None) -> xarray.Dataset:
        """A grid study's runs as one xarray Dataset over (variant, plate,
        impact_obliquity, impact_speed), SI with CF ``units`` (plate constants' as
        ``registry`` declares them; an entry point of the API: without one, the installed
        plug-ins); ParameterError if the scenes are not one full grid
        (plateimpact.storage.export.study_cube)."""
        from ..storage.export import study_cube  # noqa: PLC0415 (xarray only when asked for)

        registry = default_registry() if registry is None else registry

        return study_cube(self.study, self.runs, registry=registry)

    def to_dataframe(self, registry: PluginRegistry | None = None) -> pandas.DataFrame:
        """Every run's scenes as rows of one pandas DataFrame, indexed by (variant,
        scene): the plate, the inputs and the results in user units, each column named
        with its unit (``impact_obliquity_deg``, ``exit_speed_m_s``), the outcome by
        name; any study, grid or not. Plate constants as ``registry`` declares them
        (an entry point of the API: without one, as the study's run declared them, else
        as the installed plug-ins do). pandas is needed (``pip install
        'plateimpact[review]'``)."""
        if registry is not None:
            constants = registry.plate_constants
        else:
            constants = self.constants or default_registry().plate_constants
        study = self.study
        inputs = SceneInputs(study.scenes.columns, constants, study.plate_labels)
        columns = [run.columns for run in self.runs.values()]
        table = scene_table(inputs, study.scenes.size, columns, list(self.runs))
        return table.to_dataframe()

    def __repr__(self) -> str:
        runs = {name: run.columns for name, run in self.runs.items()}
        size = self.study.scenes.size
        return views.runs_repr("StudyResults", self.study.name, size, self.inputs, runs)

    def _repr_html_(self) -> str:
        runs = {name: run.columns for name, run in self.runs.items()}
        study = self.study
        return views.runs_html(
            "StudyResults", study.name, study.description, study.scenes.size, self.inputs, runs
        )

    def __getitem__(self, name: str) -> BatchResult:
        try:
            return self.runs[name]
        except KeyError:
            choices = ", ".join(self.runs)
            raise UnknownNameError(f"no run {name!r}; choose from: {choices}") from None

    def compare(self, run_a: str, run_b: str) -> Comparison:
        """Run B against run A: per scene Δ exit speed and obliquity (B − A), and the
        outcome changes in ranges along each plate's rows (:class:`plateimpact.Comparison`)."""
        study = self.study
        return Comparison(run_a, run_b, self[run_a], self[run_b], study.scenes, study.plate_labels)
