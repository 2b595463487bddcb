"""One step of every lane: :mod:`.stepping`'s propose, advance and judge and the step's
samples, for all the lanes at once, in the same order of operations per lane (so a
lane takes the scalar path's steps, bit for bit).

Loops run over the lanes innermost, on lane-major arrays, so that LLVM vectorises them;
what differs from lane to lane is a select. Idle lanes and lanes whose step is not used
compute too (harmless numbers): a masked vector costs what a full one does.
"""

from __future__ import annotations

from typing import Any

import numpy as np

from ...model.geometry import HALF_PI
from ..control import BRANCH_CROSSING
from .lane_motion import lane_branch_margins, lane_event_margins, lane_rates
from .lane_store import (
    ACCEPTED,
    CROSSED,
    EVENTFUL,
    FAILED,
    FINITE,
    FORCED,
    JUST_REJECTED,
    LANDING,
    MARGINS_KNOWN,
    MAX_PENETRATION,
    NEXT_STEP,
    NORM,
    PLANNED_STEP,
    STEP,
    TOTAL,
    UNIT,
    WHERE,
    WIDTH,
    Batch,
    Lanes,
    gather,
    scatter,
    scene_of,
)
from .motion import P_, THETA_, CompiledModel, branch_margins
from .stepping import Tableau, approach, crossing_fraction, error_ratio, next_step, redo_onto


def lane_combine(
    stages: Any, y: Any, h: Any, total: Any, weights: Any, h_scaled: bool, out: Any
) -> None:
    """out = y + h Σ_j weights[j] k_j per lane (or the sum alone when not
    ``h_scaled``), in stage order with zero weights skipped (:func:`~.stepping.combine`);
    ``total``: a lane row of scratch."""
    for k in range(out.shape[0]):
        for lane in range(WIDTH):
            total[lane] = 0.0
        for j in range(weights.size):
            w = weights[j]
            if w != 0.0:
                for lane in range(WIDTH):
                    total[lane] += w * stages[j, k, lane]
        if h_scaled:
            for lane in range(WIDTH):
                out[k, lane] = y[k, lane] + h[lane] * total[lane]
        else:
            for lane in range(WIDTH):
                out[k, lane] = total[lane]


def lane_propose(model: CompiledModel, tab: Tableau, lanes: Lanes, scenes: Batch) -> None:
    """Every lane's step to try into ``h``, its planned step and whether it lands on a
    branch surface (:func:`~.stepping.propose`)."""
    value, flag = lanes.value, lanes.flag
    for lane in range(WIDTH):
        h = np.minimum(value[NEXT_STEP, lane], tab.max_step * value[UNIT, lane])
        value[STEP, lane], value[PLANNED_STEP, lane], flag[LANDING, lane] = h, h, False
    if not tab.branch_landing:
        return
    for lane in range(WIDTH):  # after an event: the margins at y, lane by lane (rare)
        i = lanes.scene[lane]
        if i >= 0 and not flag[MARGINS_KNOWN, lane]:
            y, margins = gather(lanes.y, lane, lanes.one_state), lanes.one_branch
            branch_margins(model, scene_of(scenes, i), y, flag[FAILED, lane], margins)
            scatter(margins, lanes.margins, lane)
    y, derivative, trial, h = lanes.y, lanes.stages[0], lanes.trial, value[STEP]
    for k in range(y.shape[0]):
        for lane in range(WIDTH):
            trial[k, lane] = y[k, lane] + h[lane] * derivative[k, lane]
    lane_branch_margins(model, lanes, trial, lanes.ahead)
    fraction = value[WHERE]
    for lane in range(WIDTH):
        fraction[lane] = np.inf
    for r in range(lanes.margins.shape[0]):
        for lane in range(WIDTH):
            row_fraction = crossing_fraction(lanes.margins[r, lane], lanes.ahead[r, lane])
            lanes.crossing[r, lane] = (row_fraction < BRANCH_CROSSING) | flag[FORCED, lane]
            fraction[lane] = np.minimum(fraction[lane], row_fraction)
    for lane in range(WIDTH):
        h_lane, landing = approach(h[lane], fraction[lane], flag[FORCED, lane])
        value[STEP, lane], flag[LANDING, lane] = h_lane, landing


def lane_advance(model: CompiledModel, tab: Tableau, lanes: Lanes, scenes: Batch) -> None:
    """Every lane's step of its ``h``: the stages, the new state, its error and the FSAL
    stage (:func:`~.stepping.advance`)."""
    stages, y, h, total = lanes.stages, lanes.y, lanes.value[STEP], lanes.value[TOTAL]
    s = tab.C.size
    for i in range(1, s):
        lane_combine(stages, y, h, total, tab.A[i], True, lanes.trial)  # A: 0 from column i
        lane_rates(model, lanes, scenes, lanes.trial, lanes.stages[i])
    lane_combine(stages, y, h, total, tab.B, True, lanes.y_new)
    lane_rates(model, lanes, scenes, lanes.y_new, lanes.stages[s])
    lane_combine(stages, y, h, total, tab.E, False, lanes.error)
    error = lanes.error
    for k in range(error.shape[0]):
        for lane in range(WIDTH):
            error[k, lane] = h[lane] * error[k, lane]


def lane_judge(model: CompiledModel, tab: Tableau, lanes: Lanes, scenes: Batch) -> None:
    """Whether each lane's step is accepted, its next step, whether it counts as
    rejected and whether the next must cross a surface just ahead
    (:func:`~.stepping.judge`)."""
    value, flag = lanes.value, lanes.flag
    y, y_new, norm, finite = lanes.y, lanes.y_new, value[NORM], flag[FINITE]
    for lane in range(WIDTH):
        norm[lane], finite[lane] = 0.0, True
    for k in range(y.shape[0]):
        for lane in range(WIDTH):
            finite[lane] = finite[lane] & np.isfinite(y_new[k, lane])
            ratio = error_ratio(
                lanes.error[k, lane], y[k, lane], y_new[k, lane], lanes.scale[k, lane], tab.rtol
            )
            norm[lane] = ratio if k == 0 else np.maximum(norm[lane], ratio)
    for lane in range(WIDTH):  # a power each: lane by lane
        ok, h_next = next_step(
            tab, norm[lane], finite[lane], value[STEP, lane], value[PLANNED_STEP, lane],
            flag[LANDING, lane], flag[JUST_REJECTED, lane],
        )  # fmt: skip
        flag[ACCEPTED, lane], value[NEXT_STEP, lane] = ok, h_next
        flag[JUST_REJECTED, lane], flag[FORCED, lane] = not ok, False
    if not tab.branch_landing:
        return
    # A step that ended across a surface it did not plan to cross is refused and redone
    # onto it (the margins at its start are in lanes.margins since propose).
    lane_branch_margins(model, lanes, y_new, lanes.ahead)
    where, crossed = value[WHERE], flag[CROSSED]
    for lane in range(WIDTH):
        where[lane], crossed[lane] = np.inf, False
    for r in range(lanes.margins.shape[0]):
        for lane in range(WIDTH):
            start, end = lanes.margins[r, lane], lanes.ahead[r, lane]
            unplanned = (start * end < 0.0) & (lanes.crossing[r, lane] == False)  # noqa: E712
            crossed[lane] = crossed[lane] | unplanned
            fraction = start / (start - end) if unplanned else np.inf
            where[lane] = np.minimum(where[lane], fraction)
    for lane in range(WIDTH):
        if flag[ACCEPTED, lane] and crossed[lane]:
            h_again, forced = redo_onto(value[STEP, lane], where[lane])
            flag[ACCEPTED, lane], value[NEXT_STEP, lane] = False, h_again
            flag[JUST_REJECTED, lane], flag[FORCED, lane] = True, forced


def lane_sample(model: CompiledModel, tab: Tableau, lanes: Lanes, scenes: Batch) -> None:
    """Every lane's dense output, its samples and the event margins there, and whether
    anything happens in the step: a margin reaching zero, or θ rising through 90°
    (:func:`~.stepping.dense_coefficients`, :func:`~.stepping.dense_state`, the samples
    of :func:`~.scene.integrate_scene`)."""
    value, flag = lanes.value, lanes.flag
    coefficients, stages, h, y = lanes.coefficients, lanes.stages, value[STEP], lanes.y
    q_count, d = coefficients.shape[0], coefficients.shape[1]
    for q in range(q_count):
        for k in range(d):
            for lane in range(WIDTH):
                coefficients[q, k, lane] = 0.0
    for j in range(tab.P.shape[0]):
        for q in range(q_count):
            weight = tab.P[j, q]
            if weight != 0.0:
                for k in range(d):
                    for lane in range(WIDTH):
                        coefficients[q, k, lane] += weight * stages[j, k, lane]
    for q in range(q_count):
        for k in range(d):
            for lane in range(WIDTH):
                coefficients[q, k, lane] *= h[lane]
    at, samples, last = lanes.at, lanes.samples, q_count - 1
    count = at.size
    for k in range(d):
        for lane in range(WIDTH):
            samples[0, k, lane] = y[k, lane]
            samples[count - 1, k, lane] = lanes.y_new[k, lane]
    total = value[TOTAL]
    for j in range(1, count - 1):
        sigma = at[j]
        for k in range(d):  # Horner, as dense_state, the lanes innermost
            for lane in range(WIDTH):
                total[lane] = coefficients[last, k, lane] * sigma
            for q in range(last - 1, -1, -1):
                for lane in range(WIDTH):
                    total[lane] = (total[lane] + coefficients[q, k, lane]) * sigma
            for lane in range(WIDTH):
                samples[j, k, lane] = y[k, lane] + total[lane]
    for j in range(count):
        lane_event_margins(model, lanes, scenes, samples[j], lanes.event_margins[j])
    eventful, margins = flag[EVENTFUL], lanes.event_margins
    for lane in range(WIDTH):
        eventful[lane] = False
    # (& and | rather than `and` and `or`: no branch in a vector loop)
    for j in range(count - 1):
        for lane in range(WIDTH):
            below = samples[j, THETA_, lane] - HALF_PI < 0.0
            rising = below & (samples[j + 1, THETA_, lane] - HALF_PI >= 0.0)
            eventful[lane] = eventful[lane] | rising
    for j in range(1, count):
        for kind in range(margins.shape[1]):
            for lane in range(WIDTH):
                eventful[lane] = eventful[lane] | (margins[j, kind, lane] >= 0.0)


def lane_move_on(tab: Tableau, lanes: Lanes) -> None:
    """Every accepted lane in which nothing happens moves to its step's end: maximum
    penetration, state, carried derivative and margins (the usual step of
    :func:`~.scene.settle`; the driver moves its time)."""
    value, flag = lanes.value, lanes.flag
    s, count = tab.C.size, lanes.at.size
    peak, moving = value[NORM], value[TOTAL]  # moving: 1.0 where the lane moves on
    for lane in range(WIDTH):
        peak[lane] = -np.inf
    for j in range(count):
        for lane in range(WIDTH):
            peak[lane] = np.maximum(peak[lane], lanes.samples[j, P_, lane])
    for lane in range(WIDTH):
        go = flag[ACCEPTED, lane] and not flag[EVENTFUL, lane]
        moving[lane] = 1.0 if go else 0.0
        peak[lane] = np.maximum(peak[lane], lanes.y_new[P_, lane])
        if go:
            value[MAX_PENETRATION, lane] = np.maximum(value[MAX_PENETRATION, lane], peak[lane])
            flag[MARGINS_KNOWN, lane] = True
    for k in range(lanes.y.shape[0]):
        for lane in range(WIDTH):
            if moving[lane] == 1.0:
                lanes.y[k, lane] = lanes.y_new[k, lane]
                lanes.stages[0, k, lane] = lanes.stages[s, k, lane]
    if tab.branch_landing:
        for r in range(lanes.margins.shape[0]):
            for lane in range(WIDTH):
                if moving[lane] == 1.0:
                    lanes.margins[r, lane] = lanes.ahead[r, lane]


#: The functions of numbers a compiled path compiles (callees before callers).
KERNELS = (lane_combine, lane_propose, lane_advance, lane_judge, lane_sample, lane_move_on)
