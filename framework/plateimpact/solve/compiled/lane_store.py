"""What lanes of scenes keep: the batch's columns (:class:`Batch`), and a chunk's
:class:`Lanes`, every per-scene number of :mod:`.scene`'s loop stored lane-major
(``[row, lane]``, the lane last and contiguous), so that a loop over the lanes reads and
writes whole vectors."""

from __future__ import annotations

import types
from collections.abc import Callable
from typing import Any, NamedTuple

import numpy as np

from .events import EventWork
from .motion import SceneConstants
from .stepping import StepWork, Tableau

#: Scenes stepped side by side: eight vectors of doubles (AVX-512) a loop. Every loop
#: over the lanes and every call between the lane functions costs a fixed overhead
#: (arguments, the runtime check that arrays do not overlap, the loop's set-up) besides
#: its arithmetic; 64 lanes share it four times as widely as 16: 29.4 -> 18.0 us a scene
#: on the benchmark (docs/integrators.md, "Sixty-four lanes"), at the cost of batches of
#: a few dozen scenes, whose idle lanes compute too.
WIDTH = 64
#: Rows of ``Lanes.counts``: each lane's steps, accepted and rejected steps, force
#: evaluations and next trajectory row.
N_STEPS, N_ACCEPTED, N_REJECTED, N_EVALUATIONS, ROW = range(5)
#: Rows of ``Lanes.value`` [SI]: each lane's scene constants (Rs, m, rest speed, onset
#: penetration, time unit Rs/Vs, the relief plane's depth h and a row of zeros), the
#: law's drag and lift and what failure adds, the step's time, size, next and planned
#: size, the deepest penetration so far, and scratch (error norm, crossing, a sum).
(
    RADIUS, MASS, REST_SPEED, ONSET_PENETRATION, UNIT, RELIEF_DEPTH, NO_DEPTH, DRAG, LIFT,
    EXTRA_DRAG, EXTRA_LIFT, TIME, STEP, NEXT_STEP, PLANNED_STEP, MAX_PENETRATION, NORM,
    WHERE, TOTAL,
) = range(19)  # fmt: skip
#: Rows of ``Lanes.flag``: the point in eq 6's ring (intact, relieved surface); the step
#: lands on a branch, follows a rejection, must cross, may skip the margins at its
#: start; the plate failed; θ held at 180°; the step finite, accepted, across an
#: unplanned surface, with an event.
(
    RING, RELIEVED_RING, LANDING, JUST_REJECTED, FORCED, MARGINS_KNOWN, FAILED, HELD,
    FINITE, ACCEPTED, CROSSED, EVENTFUL,
) = range(12)  # fmt: skip


class Batch(NamedTuple):
    """The batch's columns: ``core`` (n, 6: Rs [m], m [kg], rest speed [m/s], onset
    penetration [m], first step [s], time unit Rs/Vs [s]), the states ``y`` (n, d), their
    error scales (n, d), the plug-ins' kernel constants, and the settings every scene
    shares."""

    core: Any
    y: Any
    scale: Any
    constants: Any
    law_constants: Any
    max_obliquity: float
    turn_back_limit: float
    adds_onset: bool
    adds_perforation: bool


def scene_of(scenes: Batch, i: int) -> SceneConstants:
    """Scene ``i``'s :class:`SceneConstants`, for the scalar kernels."""
    core = scenes.core
    return SceneConstants(
        core[i, 0], core[i, 1], core[i, 2], core[i, 3], scenes.max_obliquity,
        scenes.turn_back_limit, scenes.adds_onset, scenes.adds_perforation,
        scenes.constants[i], scenes.law_constants[i],
    )  # fmt: skip


class Lanes(NamedTuple):
    """A chunk's lanes: the scene in each (−1: none), the per-lane numbers and flags
    (``value[VALUE_ROW, lane]``, ``flag[FLAG_ROW, lane]``), state and step, stages,
    dense output, samples and margins (``[..., lane]``), counts, and one scene's arrays
    for the scalar kernels.

    Few arrays, not one per number: numba passes every array of a tuple to every
    function as separate arguments, and the compile time grows with their count."""

    scene: Any
    value: Any
    flag: Any
    counts: Any
    law: Any
    constants: Any
    scale: Any
    y: Any
    trial: Any
    y_new: Any
    error: Any
    stages: Any
    coefficients: Any
    margins: Any
    ahead: Any
    crossing: Any
    at: Any
    samples: Any
    event_margins: Any
    surface: Any
    relieved: Any
    one_state: Any
    one_rate: Any
    one_branch: Any


def lanes_scratch(
    tab: Tableau, width: int, branch_rows: int, event_samples: int, events: int,
    law_width: int, failure_width: int,
) -> tuple[Lanes, StepWork, EventWork]:  # fmt: skip
    """A chunk's lanes and :mod:`.scene`'s scratch for the steps in which an event
    happens, allocated once (the kernels that use them allocate nothing, so they run
    without reference counting). Idle lanes hold harmless numbers."""
    s, q, n = tab.C.size, tab.P.shape[1], WIDTH
    y = np.zeros((width, n))
    y[3] = 1.0  # V
    at = np.linspace(0.0, 1.0, event_samples)  # the integrator's event_samples
    work = StepWork(
        np.zeros((s + 1, width)), np.zeros(width), np.zeros(width), np.zeros(width),
        np.zeros((q, width)), np.zeros(branch_rows), np.zeros(branch_rows),
        np.zeros(branch_rows, np.bool_),
    )  # fmt: skip
    ev = EventWork(
        at, np.zeros((at.size, width)), np.zeros((at.size, events)), np.zeros(events),
        np.zeros(width), np.zeros(events),
    )  # fmt: skip
    value = np.zeros((TOTAL + 1, n))
    for row in (RADIUS, MASS, UNIT, STEP, NEXT_STEP, PLANNED_STEP):
        value[row] = 1.0
    lanes = Lanes(
        np.full(n, -1, np.int64), value, np.zeros((EVENTFUL + 1, n), np.bool_),
        np.zeros((5, n), np.int64), np.zeros((law_width, n)),
        np.zeros((failure_width, n)), np.ones((width, n)), y,
        y.copy(), y.copy(), np.zeros((width, n)), np.zeros((s + 1, width, n)),
        np.zeros((q, width, n)), np.zeros((branch_rows, n)), np.zeros((branch_rows, n)),
        np.zeros((branch_rows, n), np.bool_), at, np.zeros((at.size, width, n)),
        np.zeros((at.size, events, n)), np.zeros((6, n)), np.zeros((6, n)),
        np.zeros(width), np.zeros(width), np.zeros(branch_rows),
    )  # fmt: skip
    return lanes, work, ev


def lane_twin(function: Callable[..., Any]) -> Callable[..., Any]:
    """A copy of a kernel of numbers (the same code and module), which a lanes module
    lists in its ``INLINE`` to be inlined where its vector loops call it: LLVM vectorises
    a loop only if it calls nothing, and inlining the original everywhere would multiply
    the compile time."""
    twin = types.FunctionType(
        function.__code__, function.__globals__, function.__name__, function.__defaults__,
        function.__closure__,
    )  # fmt: skip
    twin.__module__, twin.__qualname__ = function.__module__, function.__qualname__
    twin.__doc__, twin.__annotations__ = function.__doc__, function.__annotations__
    return twin


def gather(src: Any, lane: int, out: Any) -> Any:
    """``out[:] = src[:, lane]``; ``out``."""
    for row in range(out.size):
        out[row] = src[row, lane]
    return out


def scatter(src: Any, out: Any, lane: int) -> None:
    """``out[:, lane] = src``."""
    for row in range(src.size):
        out[row, lane] = src[row]


#: The functions of numbers a compiled path compiles (callees before callers).
KERNELS = (scene_of, gather, scatter)
#: The kernels that allocate (compiled with reference counting; the rest without).
ALLOCATING = (lanes_scratch,)
