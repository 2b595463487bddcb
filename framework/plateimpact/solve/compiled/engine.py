"""A batch on the compiled path: the pair's program run over the scenes in parallel, its
per-scene results gathered as the numpy driver records them."""

from __future__ import annotations

import os
from collections.abc import Callable
from concurrent.futures import ThreadPoolExecutor
from typing import Any

import numpy as np

from ...base.errors import PluginError
from ...model import kernels
from ...model.binding import BoundBatch
from ...model.events import EVENTS, FAILURE_ONSET, PERFORATION
from ...model.impact import KINEMATIC_STATE, OBLIQUITY, SPEED, ImpactModel
from ...model.results import Outcome
from ..bounds import unfinished_error
from ..control import MAX_STEP
from ..dynamics import Dynamics
from ..integrator import Integrator
from ..recorder import ResultRecorder
from . import scene
from .building import build

#: Chunks per thread. Each chunk is every C-th scene of the batch (C chunks), so chunks
#: cost alike however a batch orders its scenes (a map's slow perforations lie side by
#: side); threads take chunks as they finish them, so a core that other work slows takes
#: fewer. Few chunks keep few lanes idle: a chunk's lanes idle as its last scenes end.
CHUNKS_PER_THREAD = 4
#: Fewest scenes in a chunk (a chunk steps WIDTH = 64 scenes together).
MIN_CHUNK = 64
_threads: list[int] = [0]  # 0: one per core


def set_threads(count: int) -> None:
    """Run the compiled path on ``count`` threads (0: one per core)."""
    _threads[0] = count


def threads() -> int:
    """The threads the compiled path runs on."""
    return _threads[0] or os.cpu_count() or 1


def run_parallel(run: Callable[..., None], n: int, arguments: tuple[Any, ...]) -> None:
    """``run(start, stop, step, *arguments)`` over scenes 0 .. n − 1 in strided chunks,
    on the threads (the compiled loop releases the GIL). A scene's result does not depend
    on its chunk or thread: each writes only its own rows."""
    chunks = max(1, min(threads() * CHUNKS_PER_THREAD, n // MIN_CHUNK))
    workers = min(threads(), chunks)
    if workers <= 1:
        run(0, n, 1, *arguments)
        return
    with ThreadPoolExecutor(workers) as pool:
        jobs = [pool.submit(run, first, n, chunks, *arguments) for first in range(chunks)]
        for future in jobs:
            future.result()


def unavailable_reason(model: ImpactModel, integrator: Integrator) -> str | None:
    """Why this model and integrator cannot run compiled (None: they can)."""
    if type(model.resistance).stress_kernel is None:
        return f"resistance {model.resistance.name!r} provides no compiled kernel"
    if type(model.failure).kernels is None:
        return f"failure {model.failure.name!r} provides no compiled kernels"
    if integrator.compiled_tableau() is None or integrator.step_control() is None:
        return f"integrator {integrator.name!r} is not an adaptive embedded Runge-Kutta pair"
    if integrator.max_seconds is not None and np.isfinite(integrator.max_seconds):
        return "a wall-time bound (max_seconds) is set"
    return None


def _check_relief(model: ImpactModel, column: object, rows: int) -> None:
    """A declared relief plane must be a row of the model's kernel constants: compiled
    code reads the row without a bounds check."""
    if isinstance(column, (int, np.integer)) and not isinstance(column, bool):
        if column == -1 or 0 <= column < rows:
            return
    raise PluginError(
        f"failure {model.failure.name!r}: FailureKernels.relief_column={column!r} is not a "
        f"row of its kernel_constants (0 to {rows - 1}, or -1 for no relief plane)"
    )


def integrate_compiled(
    model: ImpactModel, integrator: Integrator, batch: BoundBatch, recorder: ResultRecorder
) -> None:
    """Integrate every scene of ``batch`` on the compiled path into ``recorder``
    (results as :func:`~plateimpact.solve.driver.integrate` records them; trajectories
    are the numpy path's)."""
    pair = integrator.compiled_tableau()
    control = integrator.step_control()
    assert pair is not None and control is not None
    compiled = build(type(model.resistance), type(model.failure))
    n = batch.size
    width = KINEMATIC_STATE + len(model.failure.state_names)
    failure_kernels = type(model.failure).kernels
    assert failure_kernels is not None
    stats = recorder.stats
    dynamics = Dynamics(model, batch, np.zeros(n, bool), np.zeros(n, bool), stats)
    core = batch.core
    columns = (core.radius, core.mass, core.rest_speed, core.onset_penetration)
    first = integrator.initial_step(dynamics)
    table = np.ascontiguousarray(np.stack([*columns, first, dynamics.time_scale]).T)
    y = np.zeros((n, width))
    y[:, OBLIQUITY], y[:, SPEED] = core.impact_obliquity, core.impact_speed
    y[:, KINEMATIC_STATE:] = model.new_failure_state(n).T
    scale = np.ascontiguousarray(dynamics.component_scale(width).T)
    constants = np.ascontiguousarray(model.failure.kernel_constants(batch.failure).T, float)
    _check_relief(model, failure_kernels.relief_column, constants.shape[1])
    law_constants = np.ascontiguousarray(
        model.resistance.kernel_constants(batch.resistance).T, float
    )
    turn_back = ImpactModel.MAX_OBLIQUITY - ImpactModel.TURN_BACK_TOLERANCE
    floats = np.array(
        [pair.error_order, control.rtol, MAX_STEP, ImpactModel.MAX_OBLIQUITY, turn_back]
    )
    adds = [event in model.failure.events for event in (FAILURE_ONSET, PERFORATION)]
    ints = np.array(
        [control.branch_landing, *adds, integrator.max_steps,
         2 + failure_kernels.branch_rows, Outcome.EMBEDMENT, integrator.event_samples,
         0, failure_kernels.relief_column,
         failure_kernels.force_change is not kernels.no_force_change],
        dtype=np.int64,
    )  # fmt: skip
    outcomes = np.array([0 if e.outcome is None else int(e.outcome) for e in EVENTS], np.int64)
    restarts = np.array([e.restarts for e in EVENTS])
    results = np.full((n, scene.FLOAT_RESULTS), np.nan)
    counts = np.zeros((n, scene.COUNTS), np.int64)
    initial = y.copy()
    nothing = np.empty((0, 2 + width))  # no trajectory written on the first pass

    def arguments_with(*outputs: np.ndarray) -> tuple[np.ndarray, ...]:
        state, settings, results, counts, trajectory, first_rows = outputs
        return (
            table, state, scale, constants, law_constants,
            *(np.ascontiguousarray(part, float) for part in pair[:5]),
            floats, settings, outcomes, restarts, results, counts, trajectory, first_rows,
        )  # fmt: skip

    arguments = arguments_with(y, ints, results, counts, nothing, np.zeros(n, np.int64))
    run_parallel(compiled.run, n, arguments)
    _record(recorder, results, counts, batch, integrator)
    if recorder.record_trajectory:
        # A second pass writes the samples the first one counted, each scene into its
        # own rows: the same steps again (a scene's steps depend on nothing else).
        sizes = counts[:, scene.SAMPLES]
        first_rows = np.concatenate([[0], np.cumsum(sizes)[:-1]]).astype(np.int64)
        trajectory = np.empty((int(sizes.sum()), 2 + width))
        writing = ints.copy()
        writing[7] = 1
        again = (np.empty_like(results), np.empty_like(counts))
        second = arguments_with(initial, writing, *again, trajectory, first_rows)
        run_parallel(compiled.run, n, second)
        recorder.sample(
            np.repeat(np.arange(n), sizes),
            trajectory[:, scene.TIME],
            trajectory[:, 2:].T,
            trajectory[:, scene.FAILED] == 1.0,
        )


def _record(
    recorder: ResultRecorder,
    results: np.ndarray,
    counts: np.ndarray,
    batch: BoundBatch,
    integrator: Integrator,
) -> None:
    stats = recorder.stats
    stats["steps"] += int(counts[:, scene.STEPS].max(initial=0))
    stats["accepted_steps"] += int(counts[:, scene.ACCEPTED].sum())
    stats["rejected_steps"] += int(counts[:, scene.REJECTED].sum())
    stats["force_evaluations"] += int(counts[:, scene.FORCE_EVALUATIONS].sum())
    outcome = counts[:, scene.OUTCOME]
    unfinished = np.flatnonzero(outcome == 0)
    if unfinished.size:
        first = unfinished[0]
        radius, speed = batch.core.radius[first], batch.core.impact_speed[first]
        where = (
            f"at P = {results[first, scene.LAST_PENETRATION] / radius:.3g} Rs, "
            f"V = {results[first, scene.LAST_SPEED] / speed:.3g} Vs, "
            f"t = {results[first, scene.LAST_TIME] * speed / radius:.3g} Rs/Vs after "
            f"{stats['steps']} steps"
        )
        text = f"max_steps={integrator.max_steps} steps"
        raise unfinished_error(integrator, text, "max_steps", "N", unfinished, where)
    failed = counts[:, scene.PLATE_FAILED] == 1
    index = np.flatnonzero(failed)
    recorder.failed(
        index,
        results[index, scene.FAILURE_TIME],
        results[index, scene.FAILURE_PENETRATION],
        results[index, scene.FAILURE_LATERAL],
    )
    everyone = np.arange(outcome.size)
    recorder.finish(
        everyone,
        outcome.astype(np.int8),
        results[:, scene.EXIT_SPEED],
        results[:, scene.EXIT_OBLIQUITY],
        results[:, scene.CONTACT_TIME],
        results[:, scene.MAX_PENETRATION],
    )
