"""Simulation: a model and an integrator chosen by plug-in names, resolved once."""

from __future__ import annotations

from collections.abc import Callable, Iterable, Mapping
from concurrent.futures import Executor
from typing import Any

import attrs
import numpy as np

from ..base.errors import ParameterError, PluginError
from ..model.batch import SceneBatch, check_chunk_size
from ..model.binding import BoundBatch
from ..model.crater import crater_sections
from ..model.impact import REST_SPEED_FRACTION, ImpactModel, describe_plugin
from ..model.results import BatchResult, Result
from ..model.scene import Scene
from ..model.tables import SceneInputs
from ..registry.plugin_registry import PluginRegistry, default_registry
from ..solve.driver import ENGINES, choose_engine, integrate
from ..solve.integrator import Integrator
from .progress import report_scenes

#: Scenes per task when a batch is spread over an executor or a study runs in chunks:
#: large enough that the step loop's per-iteration overhead (about 1 ms) is spread over
#: many scenes, small enough to balance work and to move a progress bar.
DEFAULT_CHUNK_SIZE = 2500


def _integrator(instance: object, attribute: attrs.Attribute, value: object) -> None:
    if not isinstance(value, Integrator):
        raise PluginError(f"integrator must be an Integrator, got {value!r}")


def _engine(instance: object, attribute: attrs.Attribute, value: object) -> None:
    if value not in ENGINES:
        allowed = ", ".join(ENGINES)
        raise ParameterError("engine", f"engine must be one of {allowed}, got {value!r:.40}")


def _registry(instance: object, attribute: attrs.Attribute, value: object) -> None:
    if not isinstance(value, PluginRegistry):
        raise ParameterError("registry", f"registry must be a PluginRegistry, got {value!r:.80}")


@attrs.frozen
class Simulation:
    """Runs scenes through one resolved model and integrator.

    Build it from plug-in names with :meth:`from_names`, then call :meth:`run` for one
    scene or :meth:`run_batch` for many; the CLI does exactly this.

    ``registry`` is where the plug-ins were found; what reads or writes a plate, a run's
    inputs or stored limits for this simulation takes its declarations from there. A
    Simulation is where the library resolves an omitted registry: without one, the
    installed plug-ins (:func:`~plateimpact.default_registry`; docs/plugins.md, "Where
    the registry comes from").
    """

    model: ImpactModel
    integrator: Integrator = attrs.field(validator=_integrator)
    #: "auto" (default), "compiled" or "numpy" (``plateimpact.solve.driver.ENGINES``):
    #: how runs are integrated; the two paths agree to rounding (docs/integrators.md).
    engine: str = attrs.field(default="auto", kw_only=True, validator=_engine)
    registry: PluginRegistry = attrs.field(
        factory=default_registry, kw_only=True, eq=False, repr=False, validator=_registry
    )

    @classmethod
    def from_names(
        cls,
        resistance: str | None = None,
        failure: str | None = None,
        integrator: str | None = None,
        *,
        resistance_settings: Mapping[str, Any] | None = None,
        failure_settings: Mapping[str, Any] | None = None,
        integrator_settings: Mapping[str, Any] | None = None,
        rest_speed_fraction: float = REST_SPEED_FRACTION.default,  # type: ignore[assignment]
        registry: PluginRegistry | None = None,
        engine: str = "auto",
    ) -> Simulation:
        """Resolve each slot by name from ``registry`` (default: installed plug-ins); a
        slot not named takes the registry's default plug-in of its kind. ``engine``: see
        :attr:`engine`."""
        registry = default_registry() if registry is None else registry
        if not isinstance(registry, PluginRegistry):
            raise ParameterError("registry", f"registry must be a PluginRegistry, got {registry!r}")
        resistance = registry.default("resistance") if resistance is None else resistance
        failure = registry.default("failure") if failure is None else failure
        integrator = registry.default("integrator") if integrator is None else integrator
        for slot, given in [
            ("resistance_settings", resistance_settings),
            ("failure_settings", failure_settings),
            ("integrator_settings", integrator_settings),
        ]:
            if given is not None and not isinstance(given, Mapping):
                raise ParameterError(slot, f"{slot} must be a mapping, got {given!r:.80}")
        model = ImpactModel(
            resistance=registry.create(
                "resistance", resistance, **_settings("resistance", resistance_settings)
            ),
            failure=registry.create("failure", failure, **_settings("failure", failure_settings)),
            rest_speed_fraction=rest_speed_fraction,
        )
        settings = _settings("integrator", integrator_settings)
        created = registry.create("integrator", integrator, **settings)
        return cls(model, created, registry=registry, engine=engine)

    def run_batch(
        self,
        scenes: SceneBatch | Iterable[Scene],
        *,
        record_trajectory: bool = False,
        craters: bool = False,
        executor: Executor | None = None,
        chunk_size: int = DEFAULT_CHUNK_SIZE,
    ) -> BatchResult:
        """Results of many scenes, as arrays in the order given.

        ``craters=True`` also computes every scene's crater section (eqs 31–39; this
        records trajectories, which it needs) into ``result.craters``; it costs about
        2 ms per scene, so it is off unless asked for.

        With an ``executor`` (any :class:`concurrent.futures.Executor`: a process pool, a
        Dask client's executor) the batch goes out in chunks of ``chunk_size`` scenes,
        each run as one batch in a worker, and the results come back in order. A scene's
        result does not depend on the rest of its batch, so chunking changes nothing but
        the wall time. Threads gain nothing (the step loop holds the GIL between numpy
        calls): use processes. Inside ``plateimpact.run.progress.reporting_scenes``
        each finished chunk advances its progress bar.
        """
        batch = scenes if isinstance(scenes, SceneBatch) else SceneBatch.from_scenes(scenes)
        check_chunk_size(chunk_size)
        if executor is None:  # one process: one batch, the fastest way through the loop
            chunk_size = max(batch.size, 1)
        bound = self.model.bind(batch)
        result = run_in_chunks(
            self, bound, chunk_size, executor, record_trajectory, craters, report_scenes
        )
        # the scenes, with their plate constants' units, for the result's tables and reprs
        declared = {**self.registry.plate_constants, **self.model.plate_constants()}
        result.inputs = SceneInputs(batch.columns, declared)
        return result

    def run(self, scene: Scene, *, record_trajectory: bool = False) -> Result:
        """The result of one scene."""
        return self.run_batch([scene], record_trajectory=record_trajectory).result(0)

    def describe(self) -> dict[str, object]:
        """Each slot's plug-in name, version and settings (the model's, then the
        integrator's), and the rest rule."""
        return {**self.model.describe(), **describe_plugin("integrator", self.integrator)}


def _settings(kind: str, settings: object) -> dict[str, Any]:
    """A slot's settings: a mapping of names to values (None: none)."""
    if settings is None:
        return {}
    if not isinstance(settings, Mapping):
        raise ParameterError(
            f"{kind}_settings", f"{kind}_settings must be a mapping, got {settings!r}"
        )
    return dict(settings)


def run_in_chunks(
    simulation: Simulation,
    bound: BoundBatch,
    chunk_size: int,
    executor: Executor | None,
    record_trajectory: bool,
    craters: bool,
    advance: Callable[[int], object],
) -> BatchResult:
    """The one dispatch of a run (:meth:`Simulation.run_batch`, :meth:`Study.run`): the
    scenes of ``bound`` (bound once, so plate constants are checked and plug-ins'
    columns prepared once per run) in chunks of ``chunk_size``, in this process or on
    ``executor``, results in order; ``advance(n)`` after each chunk (a progress bar).
    A scene's result does not depend on its chunk: chunking changes only the wall time
    and how often ``advance`` is called."""
    parts = []
    # one engine for the whole run, from its size: a scene's result never depends on
    # how the run was chunked
    model, integrator = simulation.model, simulation.integrator
    engine = choose_engine(simulation.engine, model, integrator, bound.size)
    chunks = (
        bound.take(np.arange(lo, min(lo + chunk_size, bound.size)))
        if chunk_size < bound.size
        else bound
        for lo in range(0, max(bound.size, 1), chunk_size)
    )
    if executor is None:
        for chunk in chunks:
            parts.append(run_chunk(simulation, chunk, record_trajectory, craters, engine))
            advance(chunk.size)
    else:
        futures = [
            (
                executor.submit(run_chunk, simulation, chunk, record_trajectory, craters, engine),
                chunk.size,
            )
            for chunk in chunks
        ]
        for future, size in futures:
            parts.append(future.result())
            advance(size)
    return parts[0] if len(parts) == 1 else BatchResult.concat(parts)


def run_chunk(
    simulation: Simulation,
    bound: BoundBatch,
    record_trajectory: bool,
    craters: bool = False,
    engine: str | None = None,
) -> BatchResult:
    """One chunk of a run, in an executor's worker (picklable: a module function);
    crater sections, when asked for, are computed there too."""
    result = integrate(
        simulation.model,
        simulation.integrator,
        bound,
        record_trajectory=record_trajectory or craters,
        engine=simulation.engine if engine is None else engine,
    )
    if craters:
        result.craters = crater_sections(result, bound.core.radius, bound.core.thickness)
    return result


def run(scene: Scene, *, record_trajectory: bool = False, **names: Any) -> Result:
    """Run one scene; ``names`` are :meth:`Simulation.from_names` arguments."""
    return Simulation.from_names(**names).run(scene, record_trajectory=record_trajectory)
