"""One scene's event location on an accepted step: the compiled twin of
:mod:`plateimpact.solve.event_location` (samples, the first event, the crest pre-pass
for grazed events, Illinois root finding), with the same tolerances and order."""

from __future__ import annotations

from typing import Any, NamedTuple

import numpy as np

from ...model.geometry import HALF_PI
from ..event_location import MAX_ROOT_ITERATIONS, ROOT_RESOLUTION, ROOT_TOLERANCE
from .motion import THETA_, CompiledModel, SceneConstants, event_margins
from .stepping import dense_state

CREST = -1  # the "kind" of the crest's margin, θ − π/2, in locate


class EventWork(NamedTuple):
    """A scene's scratch arrays for event location: the fractions ``at`` of the step
    where it is sampled, the samples (k, d), the margins there (k, events), the margins
    at one point, a state, and the margins at the crest."""

    at: Any
    samples: Any
    margins: Any
    point_margins: Any
    state: Any
    crest_margins: Any


def margin_at(
    model: CompiledModel, scene: SceneConstants, ev: EventWork, coefficients: Any, y0: Any,
    sigma: float, kind: int, failed: bool, held: bool,
) -> float:  # fmt: skip
    """Margin ``kind`` (or the crest's) at σ on the step's dense output."""
    dense_state(coefficients, y0, sigma, ev.state)
    if kind == CREST:
        return ev.state[THETA_] - HALF_PI
    event_margins(model, scene, ev.state, failed, held, ev.point_margins)
    return ev.point_margins[kind]


def locate(
    model: CompiledModel, scene: SceneConstants, ev: EventWork, coefficients: Any, y0: Any,
    kind: int, lo: float, hi: float, f_lo: float, f_hi: float, failed: bool, held: bool,
) -> float:  # fmt: skip
    """σ in (lo, hi] where margin ``kind`` first reaches >= 0 (``event_location.locate``:
    Illinois, points kept half a tolerance inside the bracket, bisection where a margin
    is not finite)."""
    finite_lo = np.isfinite(f_lo)
    resolved = ROOT_RESOLUTION * (np.maximum(-f_lo, f_hi) if finite_lo else f_hi)
    side = 0.0
    for _ in range(MAX_ROOT_ITERATIONS):
        if not (hi - lo > ROOT_TOLERANCE and f_hi > resolved):
            break
        usable = np.isfinite(f_lo) and np.isfinite(f_hi) and f_hi > f_lo
        secant = (lo * f_hi - hi * f_lo) / (f_hi - f_lo)
        inside = np.minimum(
            np.maximum(secant, lo + 0.5 * ROOT_TOLERANCE), hi - 0.5 * ROOT_TOLERANCE
        )
        x = inside if usable and np.isfinite(secant) else 0.5 * (lo + hi)
        f = margin_at(model, scene, ev, coefficients, y0, x, kind, failed, held)
        if f >= 0.0:
            if side > 0:
                f_lo = 0.5 * f_lo  # Illinois: an end kept twice loses weight
            hi, f_hi, side = x, f, 1.0
        else:
            if side < 0:
                f_hi = 0.5 * f_hi
            lo, f_lo, side = x, f, -1.0
    return hi


def first_event(
    model: CompiledModel, scene: SceneConstants, ev: EventWork, coefficients: Any, y0: Any,
    failed: bool, held: bool,
) -> tuple[float, int, float]:  # fmt: skip
    """Where in the step (σ, inf for none) the first event happens, which one (-1 for
    none), and where θ first crosses 90° upward (σ, inf for none), from the samples and
    margins in ``ev`` (``event_location.first_event`` and ``_crest``)."""
    at, samples, margins = ev.at, ev.samples, ev.margins
    count, events = at.size, margins.shape[1]
    crest_sigma = np.inf
    crest_interval = -1
    for j in range(count - 1):
        if samples[j, THETA_] - HALF_PI < 0.0 and samples[j + 1, THETA_] - HALF_PI >= 0.0:
            crest_interval = j
            break
    any_reach = False
    for kind in range(events):
        for j in range(1, count):
            if margins[j, kind] >= 0.0:
                any_reach = True
    if not any_reach and crest_interval < 0:
        return np.inf, -1, np.inf  # nothing reaches zero: the usual step
    # The crest pre-pass: margins that rise through zero and fall back between the two
    # samples around the crest (P peaks there) are grazed; their event lies before it.
    grazed_any = False
    if crest_interval >= 0:
        j = crest_interval
        lo_turn = samples[j, THETA_] - HALF_PI
        hi_turn = samples[j + 1, THETA_] - HALF_PI
        crest_sigma = locate(
            model, scene, ev, coefficients, y0, CREST, at[j], at[j + 1], lo_turn, hi_turn,
            failed, held,
        )  # fmt: skip
        possible = False
        for kind in range(events):
            before, after = margins[j, kind], margins[j + 1, kind]
            if before < 0.0 and after < 0.0 and np.isfinite(before):
                possible = True
        if possible:
            dense_state(coefficients, y0, crest_sigma, ev.state)
            event_margins(model, scene, ev.state, failed, held, ev.crest_margins)
            grazed_any = True
    earliest = count
    for kind in range(events):
        for j in range(count - 1):
            crossing = margins[j, kind] < 0.0 and margins[j + 1, kind] >= 0.0
            if grazed_any and j == crest_interval:
                crossing = crossing or _grazed(ev, kind, j)
            if crossing:
                earliest = min(earliest, j)
                break
    if earliest == count:
        return np.inf, -1, crest_sigma
    event_sigma, event_kind = np.inf, -1
    j = earliest
    for kind in range(events):
        crossing = margins[j, kind] < 0.0 and margins[j + 1, kind] >= 0.0
        grazed = grazed_any and j == crest_interval and _grazed(ev, kind, j)
        if not (crossing or grazed):  # a kind crossing here first crosses here
            continue
        hi, f_hi = at[j + 1], margins[j + 1, kind]
        if grazed:  # the bracket ends at the crest
            hi, f_hi = crest_sigma, ev.crest_margins[kind]
        located = locate(
            model, scene, ev, coefficients, y0, kind, at[j], hi, margins[j, kind], f_hi,
            failed, held,
        )  # fmt: skip
        if located < event_sigma:  # ties go to the lower kind
            event_sigma, event_kind = located, kind
    return event_sigma, event_kind, crest_sigma


def _grazed(ev: EventWork, kind: int, j: int) -> bool:
    """Margin ``kind`` is < 0 at both samples of interval ``j`` and >= 0 at the crest."""
    margins = ev.margins
    return margins[j, kind] < 0.0 and margins[j + 1, kind] < 0.0 and ev.crest_margins[kind] >= 0.0


#: The functions of numbers a compiled path compiles (callees before callers).
KERNELS = (margin_at, locate, _grazed, first_event)
