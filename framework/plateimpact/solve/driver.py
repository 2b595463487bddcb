"""The one integration driver: every integrator's scenes go through this loop.

The driver owns what all integrators share (the scipy ``solve_ivp`` / diffrax split):
binding the batch, step-size control, the events and their order (one definition, the
model's event margins), failure onset, the θ = π hold, rest, the maximum penetration,
recording, and dropping finished scenes. The integrator only steps
(:class:`~plateimpact.solve.integrator.Integrator`).
"""

from __future__ import annotations

import importlib.util
import math
import os
import time
import warnings

import numpy as np

from ..base.errors import CompiledPathWarning, ParameterError
from ..base.extras import FAST
from ..model.batch import SceneBatch
from ..model.binding import BoundBatch
from ..model.events import EVENT_OUTCOMES, EVENTS, ONSET, RESTARTING, TURNED_BACK
from ..model.impact import KINEMATIC_STATE, LATERAL, OBLIQUITY, PENETRATION, SPEED, ImpactModel
from ..model.results import BatchResult, Outcome
from .bounds import unfinished_error
from .control import StepSizes
from .dynamics import Dynamics
from .event_location import first_event, sample_step
from .integrator import Integrator, StepperState
from .recorder import ResultRecorder

#: How a batch is integrated: "compiled" (numba; :mod:`plateimpact.solve.compiled`),
#: "numpy" (this module's loop), or "auto": compiled wherever the model's plug-ins
#: provide kernels and numba is installed.
ENGINES = ("auto", "compiled", "numpy")
#: "auto" runs every run of at least this many scenes compiled. One: the choice never
#: depends on a run's size, so a scene's result never depends on the batch or chunk it
#: ran in. Loading the compiled program costs 0.4 s a process (numba's import and its
#: cache); the numpy loop costs about 1 ms a step whatever the batch (0.25 s for even a
#: few scenes), the compiled one 30 µs a scene.
COMPILED_MIN_SCENES = 1

#: Set to "off", "auto" runs do not start compiling a program that is not ready.
WARM_VARIABLE = "PLATEIMPACT_COMPILE"

_warned: set[str] = set()
_cold: set[tuple[type, type]] = set()  # pairs found not ready: numpy for this process


def choose_engine(requested: str, model: ImpactModel, integrator: Integrator, size: int) -> str:
    """The engine a run of ``size`` scenes uses: "compiled" or "numpy".

    Under "auto", a run the compiled path cannot take (plug-ins without kernels, numba
    missing or failing) runs on the numpy path, with one warning line per process where
    numba is missing or failed; so does a run whose compiled program is not ready yet,
    while a detached process compiles it (:mod:`.compiled.warming`: no run waits for
    numba; ``plateimpact compile`` compiles every installed pair at once). A process
    keeps the numpy path for a pair it found not ready.
    """
    if requested == "numpy" or (requested == "auto" and size < COMPILED_MIN_SCENES):
        return "numpy"
    from .compiled import cache, warming  # noqa: PLC0415
    from .compiled.engine import unavailable_reason  # noqa: PLC0415

    reason = unavailable_reason(model, integrator)
    law, failure = type(model.resistance), type(model.failure)
    if reason is None and importlib.util.find_spec("numba") is None:
        reason = f"numba is not installed (pip install '{FAST}')"
        if requested == "auto":
            warn_once(reason)
    if reason is not None:
        if requested == "compiled":
            raise ParameterError("engine", f"engine 'compiled' cannot run this model: {reason}")
        return "numpy"
    if requested == "compiled":
        return "compiled"
    if (law, failure) in _cold:
        return "numpy"
    try:
        program = cache.status(law, failure)
    except (ImportError, OSError) as exc:
        warn_once(f"{type(exc).__name__}: {exc}")
        return "numpy"
    if program.ready:
        return "compiled"
    # Not ready: this process keeps the numpy path for the pair, so that one command's
    # results do not change path when the compile finishes half-way through it.
    _cold.add((law, failure))
    if program.failure:
        warn_once(program.failure)
    elif os.environ.get(WARM_VARIABLE, "background") != "off":
        try:
            warming.start(law, failure)
        except OSError as exc:
            warn_once(f"could not start compiling ({type(exc).__name__}: {exc})")
    return "numpy"


def warn_once(reason: str) -> None:
    """Say once per process why the compiled path did not run."""
    if reason not in _warned:
        _warned.add(reason)
        warnings.warn(
            f"compiled path unavailable: {reason}; running on the numpy path",
            CompiledPathWarning,
            stacklevel=3,
        )


def integrate(
    model: ImpactModel,
    integrator: Integrator,
    batch: SceneBatch | BoundBatch,
    *,
    record_trajectory: bool = False,
    engine: str = "auto",
) -> BatchResult:
    """Integrate every scene of ``batch`` from first contact, (P, Y, θ, V) = (0, 0, θs,
    Vs), to its outcome. A :class:`BoundBatch` (``model.bind``, or a part of one) is
    used as it is, so that a run bound once can be integrated in parts. ``engine``: one
    of :data:`ENGINES` (:func:`choose_engine` on this batch's size under "auto")."""
    recorder = ResultRecorder(batch.size, record_trajectory, model.failure.state_names)
    if batch.size:
        bound = batch if isinstance(batch, BoundBatch) else model.bind(batch)
        chosen = choose_engine(engine, model, integrator, bound.size)
        if chosen == "compiled" and _integrate_compiled(model, integrator, bound, recorder):
            recorder.stats["compiled_scenes"] = bound.size
        else:
            _integrate(model, integrator, bound, recorder)
    return recorder.result()


def _integrate_compiled(
    model: ImpactModel, integrator: Integrator, batch: BoundBatch, recorder: ResultRecorder
) -> bool:
    """The batch on the compiled path; False (and one warning line) where the program
    could not be built or compiled, so that the numpy path runs it instead."""
    from .compiled.building import ProgramUnavailable  # noqa: PLC0415
    from .compiled.engine import integrate_compiled  # noqa: PLC0415

    try:
        integrate_compiled(model, integrator, batch, recorder)
    except ProgramUnavailable as exc:
        warn_once(str(exc))
        return False
    return True


def _select(accepted: np.ndarray, new: StepperState, old: StepperState) -> StepperState:
    """The carried state: the new one where the step was accepted."""
    return {key: np.where(accepted, new[key], old[key]) for key in old}


class _WallTime:
    """The opt-in wall-time bound (``max_seconds``): each pass of the loop is charged in
    equal shares to the scenes it advanced, so ``used`` is what each scene still running
    has cost so far [s]."""

    def __init__(self, running: int) -> None:
        self.last, self.used, self.running = time.perf_counter(), 0.0, running

    def charge(self, running: int) -> float:
        """Charge the pass just ended; ``running``: the scenes the next one advances."""
        now = time.perf_counter()
        self.used += (now - self.last) / self.running
        self.last, self.running = now, running
        return self.used


def _progress(y: np.ndarray, t: np.ndarray, batch: BoundBatch, stats: dict) -> str:
    """Where the first unfinished scene is, in its own scales (Rs, Vs, Rs/Vs)."""
    core = batch.core
    radius, speed = core.radius[0], core.impact_speed[0]
    return (
        f"at P = {y[PENETRATION, 0] / radius:.3g} Rs, V = {y[SPEED, 0] / speed:.3g} Vs, "
        f"t = {t[0] * speed / radius:.3g} Rs/Vs after {stats['steps']} steps"
    )


def _integrate(
    model: ImpactModel, integrator: Integrator, batch: BoundBatch, recorder: ResultRecorder
) -> None:
    # Where a scene ends is decided by counted work (max_steps) alone; the clock is read
    # only when a user opted into a wall-time bound, which can end a run, never change it.
    limit = integrator.max_seconds
    clock = _WallTime(batch.size) if limit is not None and math.isfinite(limit) else None
    n = batch.size
    width = KINEMATIC_STATE + len(model.failure.state_names)
    scene = np.arange(n)
    y = np.zeros((width, n))
    y[KINEMATIC_STATE:] = model.new_failure_state(n)
    y[OBLIQUITY], y[SPEED] = batch.core.impact_obliquity, batch.core.impact_speed
    t = np.zeros(n)
    failed, held = np.zeros(n, bool), np.zeros(n, bool)
    max_pen = np.zeros(n)
    stats = recorder.stats
    dynamics = Dynamics(model, batch, failed, held, stats)
    sizes = StepSizes(
        integrator,
        integrator.initial_step(dynamics),
        dynamics.component_scale(width),
        dynamics.time_scale,
    )
    state = integrator.start(dynamics, t, y)
    at = np.linspace(0.0, 1.0, integrator.event_samples)
    recorder.sample(scene, t, y, failed)
    # The event margins at each scene's current state, where known: a step's end is the
    # next step's start unless an event changed the scene.
    margins_now, known = np.empty((len(EVENTS), n)), np.zeros(n, bool)

    for _ in range(integrator.max_steps):
        if clock is not None and limit is not None and clock.charge(scene.size) > limit:
            where = _progress(y, t, batch, stats)
            text = f"max_seconds={limit:g} s of wall time"
            raise unfinished_error(integrator, text, "max_seconds", "SECONDS", scene, where)
        stats["steps"] += 1
        step = integrator.advance(dynamics, t, y, sizes.propose(dynamics, y, state), state)
        ok = sizes.judge(step, y, dynamics)
        accepted = int(np.count_nonzero(ok))
        stats["accepted_steps"] += accepted
        stats["rejected_steps"] += ok.size - accepted
        if not accepted:
            continue
        state = _select(ok, step.state, state)

        # Accepted scenes: sample the step, find the first event in it.
        idx = np.flatnonzero(ok)
        every = accepted == ok.size  # then whole arrays, not copies, stand for the subset
        sel: slice | np.ndarray = slice(None) if every else idx
        here = dynamics if every else dynamics.take(idx)
        y0, y1, h0 = y[:, sel], step.y[:, sel], step.h[sel]
        dense = step.dense if every else step.dense.take(idx)
        margins0 = margins_now[:, sel] if known[sel].all() else None
        samples, margins = sample_step(here, y0, y1, dense, at, margins0)
        event_sigma, event_kind, crest_sigma = first_event(here, samples, margins, dense, at)
        hit = np.isfinite(event_sigma)
        end_sigma = np.where(hit, event_sigma, 1.0)
        y_end = y1.copy()
        if hit.any():  # cut at the event, on the dense output
            cut = np.flatnonzero(hit)
            y_end[:, cut] = dense.take(cut)(end_sigma[cut])
        t_end = t[sel] + end_sigma * h0

        # Maximum penetration: P at the samples, at the step's end, and where θ
        # crosses 90° upward (the crest) if that comes before the end.
        inside = at[:, np.newaxis] <= end_sigma
        peak = np.max(np.where(inside, samples[PENETRATION], -np.inf), axis=0)
        peak = np.maximum(peak, y_end[PENETRATION])
        crest_rows = np.flatnonzero(crest_sigma < end_sigma)
        if crest_rows.size:
            crest = dense.take(crest_rows)(crest_sigma[crest_rows])
            peak[crest_rows] = np.maximum(peak[crest_rows], crest[PENETRATION])
            if recorder.record_trajectory:  # the deepest point belongs to the path
                at_crest = idx[crest_rows]
                times = t[at_crest] + crest_sigma[crest_rows] * h0[crest_rows]
                recorder.sample(scene[at_crest], times, crest, failed[at_crest])
        max_pen[sel] = np.maximum(max_pen[sel], peak)
        if recorder.record_trajectory:
            for j in range(1, at.size):
                keep = at[j] < end_sigma
                if keep.any():
                    rows = idx[keep]
                    times = t[rows] + at[j] * h0[keep]
                    recorder.sample(scene[rows], times, samples[:, j, keep], failed[rows])

        # Advance; cut steps end at their event.
        y[:, sel], t[sel] = y_end, t_end
        margins_now[:, sel], known[sel] = margins[:, -1], ~hit
        status = np.zeros(y.shape[1], dtype=np.int8)
        events = idx[hit]
        kinds = event_kind[hit]
        for kind, outcome in EVENT_OUTCOMES.items():
            status[events[kinds == kind]] = outcome
        onset = events[kinds == ONSET]
        if onset.size:
            mask = np.zeros(y.shape[1], bool)
            mask[onset] = True
            failed = failed | mask
            failure_state = y[KINEMATIC_STATE:]
            model.start_failure(mask, y[PENETRATION], y[OBLIQUITY], y[SPEED], failure_state, batch)
            y[KINEMATIC_STATE:] = failure_state
            recorder.failed(scene[onset], t[onset], y[PENETRATION, onset], y[LATERAL, onset])
        if recorder.record_trajectory:  # the step's end; where the plate failed, its state
            recorder.sample(scene[sel], t_end, y[:, sel], failed[sel])
        turned = events[kinds == TURNED_BACK]
        if turned.size:
            held[turned] = True
            y[OBLIQUITY, turned] = ImpactModel.MAX_OBLIQUITY
        dynamics = Dynamics(model, batch, failed, held, stats)
        restarting = np.zeros(kinds.size, bool)
        for row in RESTARTING:  # the events after which the right-hand side is new
            restarting |= kinds == row
        restart = events[restarting]
        if restart.size:  # a new right-hand side from here: the stepper starts afresh
            state = integrator.restart(dynamics, t, y, state, restart)

        done = status > 0
        if done.any():
            exit_speed = np.where(status[done] == Outcome.EMBEDMENT, 0.0, y[SPEED, done])
            recorder.finish(
                scene[done], status[done], exit_speed, y[OBLIQUITY, done], t[done], max_pen[done]
            )
            keep = ~done
            if not keep.any():
                return
            scene, batch = scene[keep], batch.take(keep)
            y, t, max_pen = y[:, keep], t[keep], max_pen[keep]
            failed, held = failed[keep], held[keep]
            margins_now, known = margins_now[:, keep], known[keep]
            state = {key: values[..., keep] for key, values in state.items()}
            sizes.take(keep)
            dynamics = Dynamics(model, batch, failed, held, stats)
    where = _progress(y, t, batch, stats)
    text = f"max_steps={integrator.max_steps} steps"
    raise unfinished_error(integrator, text, "max_steps", "N", scene, where)
