"""Scenes stepped 64 at a time: the compiled path's batch loop.

Each lane holds one scene; every lane takes its own steps (its own size, acceptance and
events), but the lanes take them together, so the work of a step (the stages' forces,
sums, error norm, dense output, samples and margins: :mod:`.lane_steps`) is vector
arithmetic over the lanes. Only what is rare runs one lane at a time, by the scalar
path's own kernels: a step in which an event or the crest of the path falls
(:func:`~.scene.settle`), the failure model's terms, the turn-around ring. A lane whose
scene ends takes the chunk's next scene. Every lane does the scalar path's operations in
its order, so a scene's results do not depend on its lane or neighbours (tested against
:func:`~.scene.integrate_scene`).
"""

from __future__ import annotations

from typing import Any

from .events import EventWork
from .lane_steps import lane_advance, lane_judge, lane_move_on, lane_propose, lane_sample
from .lane_store import (
    ACCEPTED,
    EVENTFUL,
    FAILED,
    FORCED,
    HELD,
    JUST_REJECTED,
    MARGINS_KNOWN,
    MASS,
    MAX_PENETRATION,
    N_ACCEPTED,
    N_EVALUATIONS,
    N_REJECTED,
    N_STEPS,
    NEXT_STEP,
    ONSET_PENETRATION,
    RADIUS,
    RELIEF_DEPTH,
    REST_SPEED,
    ROW,
    STEP,
    TIME,
    UNIT,
    WIDTH,
    Batch,
    Lanes,
    gather,
    scatter,
    scene_of,
)
from .motion import P_, V_, CompiledModel, rates
from .scene import ACCEPTED as COUNT_ACCEPTED
from .scene import FORCE_EVALUATIONS as COUNT_EVALUATIONS
from .scene import (
    LAST_PENETRATION,
    LAST_SPEED,
    LAST_TIME,
    PLATE_FAILED,
    SAMPLES,
    record,
    settle,
)
from .scene import REJECTED as COUNT_REJECTED
from .scene import STEPS as COUNT_STEPS
from .stepping import StepWork, Tableau


def enter(
    model: CompiledModel, lanes: Lanes, scenes: Batch, lane: int, i: int, writing: bool,
    trajectory: Any, first_row: int,
) -> None:  # fmt: skip
    """Scene ``i`` into ``lane`` at first contact: its constants, state and carried
    derivative, its first trajectory row."""
    value, flag = lanes.value, lanes.flag
    core = scenes.core
    lanes.scene[lane] = i
    value[RADIUS, lane], value[MASS, lane] = core[i, 0], core[i, 1]
    value[REST_SPEED, lane], value[ONSET_PENETRATION, lane] = core[i, 2], core[i, 3]
    value[NEXT_STEP, lane], value[UNIT, lane] = core[i, 4], core[i, 5]
    column = model.relief_column
    value[RELIEF_DEPTH, lane] = scenes.constants[i, column] if column >= 0 else 0.0
    scatter(scenes.y[i], lanes.y, lane)
    scatter(scenes.law_constants[i], lanes.law, lane)
    scatter(scenes.constants[i], lanes.constants, lane)
    scatter(scenes.scale[i], lanes.scale, lane)
    value[TIME, lane], value[MAX_PENETRATION, lane] = 0.0, 0.0
    for row in (JUST_REJECTED, FORCED, MARGINS_KNOWN, FAILED, HELD):
        flag[row, lane] = False
    rate = lanes.one_rate
    rates(model, scene_of(scenes, i), scenes.y[i], False, False, rate)  # first same as last
    scatter(rate, lanes.stages[0], lane)
    counts = lanes.counts
    counts[N_STEPS, lane] = counts[N_ACCEPTED, lane] = counts[N_REJECTED, lane] = 0
    counts[N_EVALUATIONS, lane] = 1
    counts[ROW, lane] = record(trajectory, first_row, writing, 0.0, scenes.y[i], False)


def leave(
    lanes: Lanes, scenes: Batch, lane: int, results: Any, counts: Any, first_row: int
) -> None:
    """The lane's scene's final state and counts into its rows of the results
    (:func:`~.scene.integrate_scene`'s last lines); the lane left idle."""
    value, flag = lanes.value, lanes.flag
    i = lanes.scene[lane]
    y = gather(lanes.y, lane, scenes.y[i])
    mine, tally = results[i], counts[i]
    tally[PLATE_FAILED] = 1 if flag[FAILED, lane] else 0
    tally[COUNT_STEPS] = lanes.counts[N_STEPS, lane]
    tally[COUNT_ACCEPTED] = lanes.counts[N_ACCEPTED, lane]
    tally[COUNT_REJECTED] = lanes.counts[N_REJECTED, lane]
    tally[COUNT_EVALUATIONS] = lanes.counts[N_EVALUATIONS, lane]
    tally[SAMPLES] = lanes.counts[ROW, lane] - first_row
    mine[LAST_PENETRATION], mine[LAST_SPEED] = y[P_], y[V_]
    mine[LAST_TIME] = value[TIME, lane]
    lanes.scene[lane] = -1


def settle_lane(
    model: CompiledModel, tab: Tableau, lanes: Lanes, work: StepWork, ev: EventWork,
    scenes: Batch, lane: int,
    outcomes: Any, restarts: Any, embedment: int, results: Any, counts: Any, writing: bool,
    trajectory: Any,
) -> bool:  # fmt: skip
    """A lane's accepted step in which something happens, by the scalar path's
    :func:`~.scene.settle`: the lane's arrays copied into one scene's scratch and back.
    Whether the scene ended."""
    value, flag = lanes.value, lanes.flag
    i = lanes.scene[lane]
    for j in range(work.stages.shape[0]):
        gather(lanes.stages[j], lane, work.stages[j])
    for q in range(work.coefficients.shape[0]):
        gather(lanes.coefficients[q], lane, work.coefficients[q])
    for j in range(ev.samples.shape[0]):
        gather(lanes.samples[j], lane, ev.samples[j])
        gather(lanes.event_margins[j], lane, ev.margins[j])
    gather(lanes.y_new, lane, work.y_new)
    gather(lanes.ahead, lane, work.ahead)
    gather(lanes.margins, lane, work.margins)
    y = gather(lanes.y, lane, lanes.one_state)
    t, failed, held, peak, row, hit, restarted, ended = settle(
        model, scene_of(scenes, i), tab, work, ev, y, value[STEP, lane], value[TIME, lane],
        flag[FAILED, lane], flag[HELD, lane], value[MAX_PENETRATION, lane],
        lanes.counts[ROW, lane], writing, trajectory, outcomes, restarts, embedment,
        results[i], counts[i],
    )  # fmt: skip
    value[TIME, lane], flag[FAILED, lane], flag[HELD, lane] = t, failed, held
    value[MAX_PENETRATION, lane], lanes.counts[ROW, lane] = peak, row
    lanes.counts[N_EVALUATIONS, lane] += 1 if restarted else 0
    flag[MARGINS_KNOWN, lane] = not hit
    scatter(y, lanes.y, lane)
    scatter(work.stages[0], lanes.stages[0], lane)
    scatter(work.margins, lanes.margins, lane)
    return ended


def write_rows(lanes: Lanes, lane: int, trajectory: Any) -> None:
    """The usual step's trajectory rows of a lane: its samples inside the step, then
    its end (:func:`~.scene.settle`, when writing)."""
    value, flag = lanes.value, lanes.flag
    at, t, h = lanes.at, value[TIME, lane], value[STEP, lane]  # t: the step's start
    y, row, failed = lanes.one_state, lanes.counts[ROW, lane], flag[FAILED, lane]
    for j in range(1, at.size - 1):
        sample = gather(lanes.samples[j], lane, y)
        row = record(trajectory, row, True, t + at[j] * h, sample, failed)
    record(trajectory, row, True, t + 1.0 * h, gather(lanes.y, lane, y), failed)


def integrate_chunk(
    model: CompiledModel, tab: Tableau, lanes: Lanes, work: StepWork, ev: EventWork,
    scenes: Batch, start: int, stop: int, step: int, max_steps: int, outcomes: Any,
    restarts: Any, embedment: int, results: Any, counts: Any, writing: bool,
    trajectory: Any, first_rows: Any,
) -> None:  # fmt: skip
    """Scenes ``range(start, stop, step)`` into their rows of ``results`` and ``counts``
    (as :func:`~.scene.integrate_scene` writes them), lanes refilled as scenes end."""
    value, flag = lanes.value, lanes.flag
    following = start
    for lane in range(WIDTH):
        lanes.scene[lane] = -1
        if following < stop:
            enter(model, lanes, scenes, lane, following, writing, trajectory,
                  first_rows[following])  # fmt: skip
            following += step
    rows = lanes.at.size - 1  # a usual step's trajectory rows
    while True:
        busy = False
        for lane in range(WIDTH):
            busy = busy or lanes.scene[lane] >= 0
        if not busy:
            return
        lane_propose(model, tab, lanes, scenes)
        for lane in range(WIDTH):
            flag[MARGINS_KNOWN, lane] = True
        lane_advance(model, tab, lanes, scenes)
        lane_judge(model, tab, lanes, scenes)
        lane_sample(model, tab, lanes, scenes)
        lane_move_on(tab, lanes)
        for lane in range(WIDTH):
            i = lanes.scene[lane]
            if i < 0:
                continue
            tally = lanes.counts
            tally[N_STEPS, lane] += 1
            tally[N_EVALUATIONS, lane] += tab.C.size
            ended = False
            if not flag[ACCEPTED, lane]:
                tally[N_REJECTED, lane] += 1
            else:
                tally[N_ACCEPTED, lane] += 1
                if flag[EVENTFUL, lane]:
                    ended = settle_lane(
                        model, tab, lanes, work, ev, scenes, lane, outcomes, restarts, embedment,
                        results, counts, writing, trajectory,
                    )  # fmt: skip
                else:  # the usual step: moved on by lane_move_on, but for its time
                    if writing:
                        write_rows(lanes, lane, trajectory)
                    tally[ROW, lane] += rows
                    value[TIME, lane] = value[TIME, lane] + 1.0 * value[STEP, lane]
            if ended or tally[N_STEPS, lane] >= max_steps:
                leave(lanes, scenes, lane, results, counts, first_rows[i])
                if following < stop:
                    enter(model, lanes, scenes, lane, following, writing, trajectory,
                          first_rows[following])  # fmt: skip
                    following += step


#: The functions of numbers a compiled path compiles (callees before callers).
KERNELS = (enter, leave, settle_lane, write_rows, integrate_chunk)
