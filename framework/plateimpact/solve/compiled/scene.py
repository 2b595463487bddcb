"""One scene from first contact, (P, Y, θ, V) = (0, 0, θs, Vs), to its outcome: the
compiled twin of the numpy driver's loop (:mod:`plateimpact.solve.driver`) for one scene,
with the same steps, events, failure onset, 180° hold, maximum penetration and work
bound."""

from __future__ import annotations

from typing import Any

import numpy as np

from ...model.events import ONSET, TURNED_BACK
from .events import EventWork, first_event
from .motion import P_, STATE, THETA_, V_, Y_, CompiledModel, SceneConstants, event_margins, rates
from .motion import contact_of as _contact_of
from .stepping import StepWork, Tableau, advance, dense_coefficients, dense_state, judge, propose

#: Columns of the per-scene float results, and of the counts.
EXIT_SPEED, EXIT_OBLIQUITY, CONTACT_TIME, MAX_PENETRATION = 0, 1, 2, 3
FAILURE_TIME, FAILURE_PENETRATION, FAILURE_LATERAL = 4, 5, 6
LAST_PENETRATION, LAST_SPEED, LAST_TIME = 7, 8, 9
FLOAT_RESULTS = 10
OUTCOME, PLATE_FAILED, STEPS, ACCEPTED, REJECTED, FORCE_EVALUATIONS, SAMPLES = range(7)
COUNTS = 7
#: Columns of a trajectory row before the state: time [s], and whether the plate had failed.
TIME, FAILED = 0, 1


def copy(target: Any, source: Any) -> None:
    """target[:] = source, element by element (a slice assignment's broadcasting
    machinery costs more than the copy of a few numbers)."""
    for k in range(source.size):
        target[k] = source[k]


def record(trajectory: Any, row: int, writing: bool, time: float, y: Any, failed: bool) -> int:
    """Write a trajectory sample (time [s], failed, state) at ``row`` if ``writing``;
    the next row. Counted either way, so that a counting pass sizes the writing one."""
    if writing:
        trajectory[row, TIME] = time
        trajectory[row, FAILED] = 1.0 if failed else 0.0
        for k in range(y.size):
            trajectory[row, 2 + k] = y[k]
    return row + 1


def scratch(
    tab: Tableau, width: int, branch_rows: int, event_samples: int, events: int
) -> tuple[StepWork, EventWork, Any]:
    """The scratch arrays of one thread's scenes (allocated once per chunk: the kernels
    that use them allocate nothing, so they run without reference counting)."""
    s = tab.C.size
    work = StepWork(
        np.empty((s + 1, width)), np.empty(width), np.empty(width), np.empty(width),
        np.empty((tab.P.shape[1], width)), np.empty(branch_rows), np.empty(branch_rows),
        np.zeros(branch_rows, np.bool_),
    )  # fmt: skip
    at = np.linspace(0.0, 1.0, event_samples)  # the integrator's event_samples
    ev = EventWork(
        at, np.empty((at.size, width)), np.empty((at.size, events)), np.empty(events),
        np.empty(width), np.empty(events),
    )  # fmt: skip
    return work, ev, np.empty(events)


def settle(
    model: CompiledModel, scene: SceneConstants, tab: Tableau, work: StepWork, ev: EventWork,
    y: Any, h: float, t: float, failed: bool, held: bool, max_penetration: float, row: int,
    writing: bool, trajectory: Any, outcomes: Any, restarts: Any, embedment: int,
    results: Any, counts: Any,
) -> tuple[float, bool, bool, float, int, bool, bool, bool]:  # fmt: skip
    """An accepted step of length ``h`` [s] from ``y`` at time ``t`` [s], whose dense
    output, samples and event margins are in ``work`` and ``ev``: its first event, the
    maximum penetration and the trajectory rows up to it, and ``y`` moved to the step's
    end or the event (with the carried derivative in ``work.stages[0]``). Returns the new
    time [s], failed, held, maximum penetration [m] and next row, and whether an event
    happened, whether the right-hand side was restarted (one more evaluation) and
    whether the scene ended (its results written)."""
    at, samples = ev.at, ev.samples
    s = tab.C.size
    event_sigma, kind, crest_sigma = first_event(
        model, scene, ev, work.coefficients, y, failed, held
    )
    hit = np.isfinite(event_sigma)
    end_sigma = event_sigma if hit else 1.0
    # Maximum penetration: at the samples inside the step, its end, and the crest.
    peak = -np.inf
    for j in range(at.size):
        if at[j] <= end_sigma:
            peak = np.maximum(peak, samples[j, P_])
    if hit:
        dense_state(work.coefficients, y, end_sigma, ev.state)
    else:
        copy(ev.state, work.y_new)
    peak = np.maximum(peak, ev.state[P_])
    if crest_sigma < end_sigma:
        dense_state(work.coefficients, y, crest_sigma, work.trial)
        peak = np.maximum(peak, work.trial[P_])
        # the deepest point belongs to the path
        row = record(trajectory, row, writing, t + crest_sigma * h, work.trial, failed)
    max_penetration = np.maximum(max_penetration, peak)
    for j in range(1, at.size):
        if at[j] < end_sigma:
            row = record(trajectory, row, writing, t + at[j] * h, samples[j], failed)
    t = t + end_sigma * h
    copy(y, ev.state)
    copy(work.stages[0], work.stages[s])  # the carried derivative (FSAL)
    if not hit:
        if tab.branch_landing:  # judge's margins at the step's end: now y's
            copy(work.margins, work.ahead)
        row = record(trajectory, row, writing, t, y, failed)  # the step's end
        return t, failed, held, max_penetration, row, False, False, False
    if kind == ONSET:
        failed = True
        if y.size > STATE:
            contact = _contact_of(model, scene, y, y[THETA_], np.nan)
            model.initial_state(contact, y[STATE:])
        results[FAILURE_TIME], results[FAILURE_PENETRATION] = t, y[P_]
        results[FAILURE_LATERAL] = y[Y_]
    row = record(trajectory, row, writing, t, y, failed)  # the step's end
    if kind == TURNED_BACK:
        held = True
        y[THETA_] = scene.max_obliquity
    restarted = restarts[kind]
    if restarted:  # a new right-hand side from here: the stepper starts afresh
        rates(model, scene, y, failed, held, work.stages[0])
    ended = outcomes[kind] > 0
    if ended:
        results[EXIT_SPEED] = 0.0 if outcomes[kind] == embedment else y[V_]
        results[EXIT_OBLIQUITY] = np.abs(y[THETA_])
        results[CONTACT_TIME] = t
        results[MAX_PENETRATION] = max_penetration
        counts[OUTCOME] = outcomes[kind]
    return t, failed, held, max_penetration, row, True, restarted, ended


def integrate_scene(
    model: CompiledModel, scene: SceneConstants, tab: Tableau, work: StepWork, ev: EventWork,
    known_margins: Any, y: Any, scale: Any, h_first: float, unit: float, max_steps: int,
    outcomes: Any, restarts: Any, embedment: int, results: Any, counts: Any,
    writing: bool, trajectory: Any, first_row: int,
) -> None:  # fmt: skip
    """Integrate the scene whose initial state is ``y`` (changed in place) and write its
    results into ``results`` and ``counts`` (outcome 0: unfinished after ``max_steps``).
    ``outcomes`` and ``restarts``: each event's outcome code (0: goes on) and whether
    the right-hand side changes there (from :data:`plateimpact.model.events.EVENTS`).
    Trajectory samples, where the numpy driver records them, are counted in ``counts``
    and, if ``writing``, written to ``trajectory`` from ``first_row``. ``work``, ``ev``
    and ``known_margins``: scratch arrays (:func:`scratch`)."""
    d = y.size
    s = tab.C.size
    at = ev.at
    known = False
    failed = held = d < 0  # False, typed as a plain bool (a literal would compile twice)
    t = 0.0
    max_penetration = 0.0
    h_next, just_rejected, forced = h_first, False, False
    margins_known = False  # work.margins holds the branch margins at y
    rates(model, scene, y, failed, held, work.stages[0])  # first same as last
    evaluations = 1
    row = record(trajectory, first_row, writing, t, y, failed)
    accepted = rejected = steps = 0
    for _ in range(max_steps):
        steps += 1
        h, planned, landing = propose(
            model, scene, tab, work, y, h_next, unit, failed, forced, margins_known
        )
        forced, margins_known = False, True
        advance(model, scene, tab, work, y, h, failed, held)
        evaluations += s
        ok, h_next, just_rejected, forced = judge(
            model, scene, tab, work, y, scale, h, planned, landing, just_rejected, failed
        )
        if not ok:
            rejected += 1
            continue
        accepted += 1
        # Sample the step; find the first event in it.
        dense_coefficients(tab, work, h)
        samples, margins = ev.samples, ev.margins
        copy(samples[0], y)
        copy(samples[at.size - 1], work.y_new)
        for j in range(1, at.size - 1):
            dense_state(work.coefficients, y, at[j], samples[j])
        for j in range(at.size):
            if j == 0 and known:
                copy(margins[0], known_margins)
            else:
                event_margins(model, scene, samples[j], failed, held, margins[j])
        copy(known_margins, margins[at.size - 1])
        t, failed, held, max_penetration, row, hit, restarted, ended = settle(
            model, scene, tab, work, ev, y, h, t, failed, held, max_penetration, row,
            writing, trajectory, outcomes, restarts, embedment, results, counts,
        )  # fmt: skip
        known = margins_known = not hit
        evaluations += 1 if restarted else 0
        if ended:
            break
    counts[PLATE_FAILED] = 1 if failed else 0
    counts[STEPS], counts[ACCEPTED], counts[REJECTED] = steps, accepted, rejected
    counts[FORCE_EVALUATIONS] = evaluations
    counts[SAMPLES] = row - first_row
    results[LAST_PENETRATION], results[LAST_SPEED], results[LAST_TIME] = y[P_], y[V_], t


#: The functions of numbers a compiled path compiles.
KERNELS = (copy, record, settle, integrate_scene)
#: The kernels that allocate (compiled with reference counting; the rest without).
ALLOCATING = (scratch,)
