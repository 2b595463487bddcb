"""One scene's step: an explicit embedded Runge–Kutta pair with FSAL and dense output
(the tableau of :class:`~plateimpact.solve.integrator.Tableau`), its error control and
its landing on branch surfaces, as numbers: the compiled twin of
:class:`plateimpact.solve.control.StepSizes` and ``EmbeddedRungeKutta.advance``, in the
same order of operations (so that the two paths take the same steps).

``work`` is a :class:`StepWork` of one scene's scratch arrays; each function returns the
new values of what it changes.
"""

from __future__ import annotations

from typing import Any, NamedTuple

import numpy as np

from ..control import BRANCH_APPROACH, BRANCH_CROSSING, MAX_FACTOR, MIN_FACTOR, SAFETY
from .motion import CompiledModel, SceneConstants, branch_margins, rates


class Tableau(NamedTuple):
    """C (s,), A (s, s), B (s,), E (s + 1,: the last for the FSAL stage), the dense
    output P (s + 1, Q), the error order, and the error control: rtol, the largest step
    [fraction of Rs/Vs], whether steps land on branch surfaces."""

    C: Any
    A: Any
    B: Any
    E: Any
    P: Any
    error_order: float
    rtol: float
    max_step: float
    branch_landing: bool


class StepWork(NamedTuple):
    """A scene's scratch arrays: the stages (s + 1, d), the trial and new state, the
    error, the dense coefficients (Q, d), the branch margins now and at a trial point,
    and which branch rows the step crosses on purpose."""

    stages: Any
    trial: Any
    y_new: Any
    error: Any
    coefficients: Any
    margins: Any
    ahead: Any
    crossing: Any


def propose(
    model: CompiledModel, scene: SceneConstants, tab: Tableau, work: StepWork, y: Any,
    h_next: float, unit: float, failed: bool, forced: bool, margins_known: bool,
) -> tuple[float, float, bool]:  # fmt: skip
    """The step to attempt [s], the step it was planned to be, and whether it is
    shortened to land on a branch surface (``StepSizes.propose`` and
    ``approach_branches``: the Euler prediction y + h f(y) of the surfaces).
    ``margins_known``: ``work.margins`` already holds the branch margins at ``y``."""
    h = np.minimum(h_next, tab.max_step * unit)
    if not tab.branch_landing:
        return h, h, False
    planned = h
    derivative = work.stages[0]
    if not margins_known:
        branch_margins(model, scene, y, failed, work.margins)
    for k in range(y.size):
        work.trial[k] = y[k] + h * derivative[k]
    branch_margins(model, scene, work.trial, failed, work.ahead)
    fraction = np.inf
    for r in range(work.margins.size):
        row_fraction = crossing_fraction(work.margins[r], work.ahead[r])
        work.crossing[r] = row_fraction < BRANCH_CROSSING
        fraction = np.minimum(fraction, row_fraction)
    if forced:  # a surface found just ahead by a refused step: crossed now, as judged
        for r in range(work.crossing.size):
            work.crossing[r] = True
    h_try, landing = approach(h, fraction, forced)
    return h_try, planned, landing


def crossing_fraction(now: float, ahead: float) -> float:
    """Where between two points a branch margin changes sign, as a fraction of the way
    from the first (margins ``now`` and ``ahead`` [m]); inf if it does not."""
    return now / (now - ahead) if now * ahead < 0.0 else np.inf


def approach(h: float, fraction: float, forced: bool) -> tuple[float, bool]:
    """The step [s] to try for a step ``h`` [s] whose nearest surface is ``fraction`` of
    the way along it, and whether it lands there (``approach_branches``): across a
    surface just ahead (or ``forced`` across), onto one further on, else ``h``."""
    if forced:
        return h, False
    if fraction < BRANCH_CROSSING:
        return BRANCH_CROSSING * h, False
    if fraction < 1.0:
        return BRANCH_APPROACH * fraction * h, True
    return h, False


def advance(
    model: CompiledModel, scene: SceneConstants, tab: Tableau, work: StepWork, y: Any,
    h: float, failed: bool, held: bool,
) -> None:  # fmt: skip
    """One step of length ``h`` [s] from ``y`` (stage 0: the carried derivative): the new
    state, its error estimate and the FSAL stage into ``work``
    (``EmbeddedRungeKutta.advance``; sums in stage order, zero weights skipped)."""
    stages, s = work.stages, tab.C.size
    for i in range(1, s):
        combine(tab.A[i], stages, y, h, work.trial)  # A is zero from column i on: skipped
        rates(model, scene, work.trial, failed, held, stages[i])
    combine(tab.B, stages, y, h, work.y_new)
    rates(model, scene, work.y_new, failed, held, stages[s])
    combine(tab.E, stages, y, 0.0, work.error)
    for k in range(y.size):
        work.error[k] = h * work.error[k]


def combine(weights: Any, stages: Any, y: Any, h: float, out: Any) -> None:
    """out = y + h Σ_j weights[j] · stages[j] (or, with h = 0, the sum Σ_j alone), summed
    in stage order with zero weights skipped, component by component: the numpy
    stepper's ``_combine``."""
    for k in range(out.size):
        total = 0.0
        for j in range(weights.size):
            if weights[j] != 0.0:
                total += weights[j] * stages[j, k]
        out[k] = total if h == 0.0 else y[k] + h * total


def judge(
    model: CompiledModel, scene: SceneConstants, tab: Tableau, work: StepWork, y: Any,
    scale: Any, h: float, planned: float, landing: bool, just_rejected: bool, failed: bool,
) -> tuple[bool, float, bool, bool]:  # fmt: skip
    """Whether the step is accepted, the next step [s], whether this one counts as
    rejected, and whether the next must cross a surface just ahead (``StepSizes.judge``
    and ``_refuse_unplanned_crossings``)."""
    finite = True
    norm = 0.0
    for k in range(y.size):
        finite = finite and np.isfinite(work.y_new[k])
        ratio = error_ratio(work.error[k], y[k], work.y_new[k], scale[k], tab.rtol)
        norm = ratio if k == 0 else np.maximum(norm, ratio)
    ok, h_next = next_step(tab, norm, finite, h, planned, landing, just_rejected)
    if not (tab.branch_landing and ok):
        return ok, h_next, not ok, False
    # A step that ended across a surface it did not plan to cross is refused and redone
    # onto it (the margins at its start are in work.margins since propose).
    branch_margins(model, scene, work.y_new, failed, work.ahead)
    where = np.inf
    crossed = False
    for r in range(work.margins.size):
        start, end = work.margins[r], work.ahead[r]
        if start * end < 0.0 and not work.crossing[r]:
            crossed = True
            where = np.minimum(where, start / (start - end))
    if not crossed:
        return True, h_next, False, False
    h_again, forced = redo_onto(h, where)
    return False, h_again, True, forced


def error_ratio(error: float, y0: float, y1: float, scale: float, rtol: float) -> float:
    """A component's error [its unit] over its tolerance, rtol · max(scale, |y0|, |y1|)
    at the step's two ends (``StepSizes.judge``'s norm, one component)."""
    size = np.maximum(scale, np.maximum(np.abs(y0), np.abs(y1)))
    return np.abs(error) / (rtol * size)


def next_step(
    tab: Tableau, norm: float, finite: bool, h: float, planned: float, landing: bool,
    just_rejected: bool,
) -> tuple[bool, float]:  # fmt: skip
    """Whether a step of ``h`` [s] with error ``norm`` (and a finite end) is accepted,
    and the next step [s] (``StepSizes.judge``)."""
    ok = np.isfinite(norm) and finite and norm <= 1.0
    factor = np.minimum(
        np.maximum(SAFETY * np.power(norm, -1.0 / tab.error_order), MIN_FACTOR), MAX_FACTOR
    )
    if not np.isfinite(factor):
        factor = MIN_FACTOR
    if just_rejected or not ok:
        factor = np.minimum(factor, 1.0)
    if tab.branch_landing and landing and ok:  # resume the planned step after landing
        factor = planned / h
    return ok, h * factor


def redo_onto(h: float, where: float) -> tuple[float, bool]:
    """The step [s] that redoes a step ``h`` [s] which crossed a surface it did not plan
    to, ``where`` of the way along it: onto it, or across it if it lies just ahead (then
    the next proposal is forced across)."""
    if where < BRANCH_CROSSING:
        return BRANCH_CROSSING * h, True
    return BRANCH_APPROACH * where * h, False


def dense_coefficients(tab: Tableau, work: StepWork, h: float) -> None:
    """The dense output's polynomial coefficients c_q = h Σ_j P[j, q] k_j, stage by stage
    (``RungeKuttaDense.polynomial``)."""
    coefficients = work.coefficients
    for q in range(coefficients.shape[0]):
        for k in range(coefficients.shape[1]):
            coefficients[q, k] = 0.0
    for j in range(tab.P.shape[0]):
        for q in range(tab.P.shape[1]):
            if tab.P[j, q] != 0.0:
                for k in range(coefficients.shape[1]):
                    coefficients[q, k] += tab.P[j, q] * work.stages[j, k]
    for q in range(coefficients.shape[0]):
        for k in range(coefficients.shape[1]):
            coefficients[q, k] *= h


def dense_state(coefficients: Any, y0: Any, sigma: float, out: Any) -> None:
    """y(σ) = y0 + σ(c_0 + σ(c_1 + ...)) into ``out`` (Horner, as
    ``PolynomialDenseOutput``)."""
    last = coefficients.shape[0] - 1
    for k in range(y0.size):
        total = coefficients[last, k] * sigma
        for q in range(last - 1, -1, -1):
            total = (total + coefficients[q, k]) * sigma
        out[k] = y0[k] + total


#: The functions of numbers a compiled path compiles (callees before callers).
KERNELS = (
    crossing_fraction,
    approach,
    error_ratio,
    next_step,
    redo_onto,
    combine,
    propose,
    advance,
    judge,
    dense_coefficients,
    dense_state,
)
