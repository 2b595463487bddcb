"""Event location on the dense output of accepted steps: sampling, the first event, and
the root finding (docs/integrators.md, "events are never stepped over")."""

from __future__ import annotations

from collections.abc import Callable

import numpy as np

from ..model.events import EVENTS
from ..model.impact import OBLIQUITY
from .dense import DenseOutput
from .dynamics import Dynamics

MAX_ROOT_ITERATIONS = 16  # Illinois converges superlinearly; more only chases rounding
ROOT_TOLERANCE = 1e-13  # event time to this fraction of the step
ROOT_RESOLUTION = 1e-10  # or a margin this small against its values at the samples


def sample_step(
    dynamics: Dynamics,
    y0: np.ndarray,
    y1: np.ndarray,
    dense: DenseOutput,
    at: np.ndarray,
    margins0: np.ndarray | None = None,
) -> tuple[np.ndarray, np.ndarray]:
    """The states at the fractions ``at`` of the step (0 and 1 included), shape
    (d, samples, m), and the event margins there, shape (events, samples, m). The ends are
    the step's own states; only the interior comes from the dense output. One margin call
    per sample, on the batch as it is (no repeated copy of its columns); ``margins0``, the
    margins at the start if already known (the end of the previous step), saves one."""
    samples = np.empty((y0.shape[0], at.size, y0.shape[1]))
    samples[:, 0], samples[:, -1] = y0, y1
    for j in range(1, at.size - 1):
        samples[:, j] = dense(at[j])
    margins = np.empty((len(EVENTS), at.size, y0.shape[1]))
    for j in range(at.size):
        if j == 0 and margins0 is not None:
            margins[:, 0] = margins0
        else:
            margins[:, j] = dynamics.event_margins(samples[:, j])
    return samples, margins


def first_event(
    dynamics: Dynamics, samples: np.ndarray, margins: np.ndarray, dense: DenseOutput, at: np.ndarray
) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Where in the step (σ, inf for none) the first event happens, which one (-1 for
    none), and where θ first crosses 90° upward (σ, inf for none).

    A margin crosses where it goes from < 0 at one sample to >= 0 at the next. Only
    the events in a scene's earliest such interval can come first; those and the
    crest are refined together, in one root-finding loop over (scene, kind) pairs.
    Ties go to the lower event kind, as in :data:`EVENT_NAMES` order.
    """
    m = samples.shape[2]
    event_sigma, event_kind = np.full(m, np.inf), np.full(m, -1)
    crest_sigma = np.full(m, np.inf)
    turning = samples[OBLIQUITY] - 0.5 * np.pi  # the crest's margin
    cresting = (turning[:-1] < 0.0) & (turning[1:] >= 0.0)
    if margins[:, 1:].max() < 0.0 and not cresting.any():
        return event_sigma, event_kind, crest_sigma  # nothing reaches zero: the usual step
    crest_rows, crest_at, grazed = _crest(dynamics, margins, turning, cresting, dense, at)
    crest_sigma[crest_rows] = crest_at
    crossing = (margins[:, :-1] < 0.0) & (margins[:, 1:] >= 0.0)
    for kind, row, interval, _, _ in grazed:
        crossing[kind, interval, row] = True
    has = np.asarray(crossing.any(axis=1))
    first = np.argmax(crossing, axis=1)  # (events, m)
    earliest = np.where(has, first, at.size).min(axis=0)
    kinds, rows = np.nonzero(has & (first == earliest))
    if not rows.size:
        return event_sigma, event_kind, crest_sigma
    lo = first[kinds, rows]
    pairs = dynamics.take(rows)
    pair = np.arange(rows.size)
    needed = frozenset(int(k) for k in np.unique(kinds))

    def margin(state: np.ndarray) -> np.ndarray:
        return pairs.event_margins(state, needed)[kinds, pair]

    hi, f_hi = at[lo + 1], margins[kinds, lo + 1, rows]
    for kind, row, interval, sigma, value in grazed:  # the bracket ends at the crest
        at_pair = (kinds == kind) & (rows == row) & (lo == interval)
        hi, f_hi = np.where(at_pair, sigma, hi), np.where(at_pair, value, f_hi)
    located = locate(margin, dense.take(rows), at[lo], hi, margins[kinds, lo, rows], f_hi)
    order = np.lexsort((kinds, located, rows))
    unique_rows, first_pair = np.unique(rows[order], return_index=True)
    event_sigma[unique_rows] = located[order][first_pair]
    event_kind[unique_rows] = kinds[order][first_pair]
    return event_sigma, event_kind, crest_sigma


def _crest(
    dynamics: Dynamics,
    margins: np.ndarray,
    turning: np.ndarray,
    cresting: np.ndarray,
    dense: DenseOutput,
    at: np.ndarray,
) -> tuple[np.ndarray, np.ndarray, list[tuple[int, int, int, float, float]]]:
    """Where θ first crosses 90° upward in the step (the scenes, their σ), and the events
    that the step's samples miss because their margin rises through zero and falls back
    between two samples around that crest (where P peaks: failure onset when the deepest
    penetration just passes P*): (kind, scene, interval, σ of the crest, margin there)
    for each margin that is < 0 at both samples of the crest's interval and >= 0 at the
    crest itself; its event lies between the interval's start and the crest. Elsewhere P
    is monotone within a step, and a sign change at the samples is exact for the margins
    that follow it."""
    rows = np.flatnonzero(cresting.any(axis=0))
    if not rows.size:
        return rows, np.empty(0), []
    interval = np.argmax(cresting[:, rows], axis=0)

    def crest_margin(state: np.ndarray) -> np.ndarray:
        return state[OBLIQUITY] - 0.5 * np.pi

    part = dense.take(rows)
    lo, hi = at[interval], at[interval + 1]
    sigma = locate(crest_margin, part, lo, hi, turning[interval, rows], turning[interval + 1, rows])
    before, after = margins[:, interval, rows], margins[:, interval + 1, rows]
    # Only a finite margin below zero at both samples can be grazed (-inf: an event that
    # cannot happen there): the margins at the crest are evaluated for those scenes.
    possible = ((before < 0.0) & (after < 0.0) & np.isfinite(before)).any(axis=0)
    if not possible.any():
        return rows, sigma, []
    near = np.flatnonzero(possible)
    at_crest = dynamics.take(rows[near]).event_margins(part.take(near)(sigma[near]))
    grazed = (before[:, near] < 0.0) & (after[:, near] < 0.0) & (at_crest >= 0.0)
    return (
        rows,
        sigma,
        [
            (
                int(k),
                int(rows[near[j]]),
                int(interval[near[j]]),
                float(sigma[near[j]]),
                float(at_crest[k, j]),
            )
            for k, j in zip(*np.nonzero(grazed), strict=True)
        ],  # fmt: skip
    )


def locate(
    margin: Callable[[np.ndarray], np.ndarray],
    dense: DenseOutput,
    lo: np.ndarray,
    hi: np.ndarray,
    f_lo: np.ndarray,
    f_hi: np.ndarray,
) -> np.ndarray:
    """σ in (lo, hi] where ``margin(state)`` first reaches >= 0 on the dense output;
    f_lo < 0 <= f_hi are its values at lo and hi.

    Illinois (modified regula falsi), its points kept half a tolerance inside the
    bracket; bisection where a margin is not finite. Each row stops on its own, once
    its bracket is below ROOT_TOLERANCE of the step or its margin at hi is below
    ROOT_RESOLUTION of its values at the samples, so a scene's result never depends
    on the other scenes of its batch (benchmarks/event_location.py counts iterations).
    """
    lo, hi, f_lo, f_hi = lo.copy(), hi.copy(), f_lo.copy(), f_hi.copy()
    resolved = ROOT_RESOLUTION * np.where(np.isfinite(f_lo), np.maximum(-f_lo, f_hi), f_hi)
    side = np.zeros(lo.size)
    for _ in range(MAX_ROOT_ITERATIONS):
        # A row is done when its bracket is closed, or when its margin at hi is within
        # ROOT_RESOLUTION of its size at the samples: there a margin that is a
        # difference of larger lengths is down to rounding, and further points only
        # bounce from side to side of a root that rounding has already blurred.
        open_ = (hi - lo > ROOT_TOLERANCE) & (f_hi > resolved)
        if not open_.any():
            break
        usable = np.isfinite(f_lo) & np.isfinite(f_hi) & (f_hi > f_lo)
        with np.errstate(invalid="ignore", divide="ignore"):
            secant = (lo * f_hi - hi * f_lo) / (f_hi - f_lo)
        # The secant point, kept at least half a tolerance inside the bracket
        # (Dekker): where it has converged onto one end, rounding puts it on that end,
        # and the next point must land just across the root to close the bracket
        # rather than fall back to bisection and creep up on it.
        inside = np.clip(secant, lo + 0.5 * ROOT_TOLERANCE, hi - 0.5 * ROOT_TOLERANCE)
        x = np.where(usable & np.isfinite(secant), inside, 0.5 * (lo + hi))
        f = margin(dense(x))
        after = (f >= 0.0) & open_
        before = ~(f >= 0.0) & open_
        f_lo = np.where(after & (side > 0), 0.5 * f_lo, f_lo)  # Illinois: an end kept
        f_hi = np.where(before & (side < 0), 0.5 * f_hi, f_hi)  # twice loses weight
        hi, f_hi = np.where(after, x, hi), np.where(after, f, f_hi)
        lo, f_lo = np.where(before, x, lo), np.where(before, f, f_lo)
        side = np.where(after, 1.0, np.where(before, -1.0, side))
    return hi
