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

#: Scenes stepped side by side: the widest vector of doubles (AVX-512); narrower
#: machines run two or four vector operations per loop.
WIDTH = 16
#: Rows of ``Lanes.counts``: each lane's steps, accepted and rejected steps, force
#: evaluations and next trajectory row.
STEPS, ACCEPTED, REJECTED, EVALUATIONS, ROW = range(5)


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
    """A chunk's lanes: the scene in each (−1: none) and its constants, state and step,
    stages, dense output, samples and margins (``[..., lane]``), per-lane flags and
    counts, one scene's arrays for the scalar kernels, and :mod:`.scene`'s scratch for
    the steps in which an event happens."""

    scene: Any
    radius: Any
    mass: Any
    rest_speed: Any
    onset_penetration: Any
    unit: Any
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
    samples: Any
    event_margins: Any
    surface: Any
    ring: Any
    stress: Any
    law: Any
    drag: Any
    lift: Any
    depth: Any
    no_depth: Any
    relieved: Any
    relieved_ring: Any
    extra_drag: Any
    extra_lift: Any
    t: Any
    h: Any
    h_next: Any
    planned: Any
    max_penetration: Any
    norm: Any
    where: Any
    total: Any
    landing: Any
    just_rejected: Any
    forced: Any
    margins_known: Any
    failed: Any
    held: Any
    finite: Any
    accepted: Any
    crossed: Any
    eventful: Any
    counts: Any
    one_state: Any
    one_rate: Any
    one_branch: Any
    one_event: Any
    work: StepWork
    ev: EventWork


def lanes_scratch(
    tab: Tableau, width: int, branch_rows: int, event_samples: int, events: int,
    law_width: int,
) -> Lanes:  # fmt: skip
    """A chunk's lanes, allocated once (the kernels that use them allocate nothing, so
    they run without reference counting). Idle lanes hold harmless numbers."""
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
    ones, zeros = np.ones(n), np.zeros(n)
    flags = [np.zeros(n, np.bool_) for _ in range(10)]
    return Lanes(
        np.full(n, -1, np.int64), ones.copy(), ones.copy(), zeros.copy(), zeros.copy(),
        ones.copy(), np.ones((width, n)), y, y.copy(), y.copy(), np.zeros((width, n)),
        np.zeros((s + 1, width, n)), np.zeros((q, width, n)), np.zeros((branch_rows, n)),
        np.zeros((branch_rows, n)), np.zeros((branch_rows, n), np.bool_),
        np.zeros((at.size, width, n)), np.zeros((at.size, events, n)), np.zeros((6, n)),
        np.zeros(n, np.bool_), zeros.copy(), np.zeros((law_width, n)),
        zeros.copy(), zeros.copy(), zeros.copy(), zeros.copy(), np.zeros((6, n)),
        np.zeros(n, np.bool_), zeros.copy(), zeros.copy(),
        zeros.copy(), ones.copy(), ones.copy(),
        ones.copy(), zeros.copy(), zeros.copy(), zeros.copy(), zeros.copy(),
        flags[0], flags[1], flags[2], flags[3], flags[4], flags[5], flags[6], flags[7],
        flags[8], flags[9], np.zeros((5, n), np.int64), np.zeros(width), np.zeros(width),
        np.zeros(branch_rows), np.zeros(events), work, ev,
    )  # fmt: skip


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
