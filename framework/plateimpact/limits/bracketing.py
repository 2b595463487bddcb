"""Locating the boundaries between regimes along many lines at once (docs/limits.md).

The finder knows nothing of impacts: it asks ``evaluate(line, x)`` for the regime codes
at points ``x`` of lines ``line`` (one batch per call) and returns, for every line, the
brackets [low, high] of width <= tolerance across which the regime changes.

1. **Scan.** Every line is sampled at equal spacing h <= resolution, both ends included,
   all lines in one batch. A band of width >= h contains a sample, so it is seen: this is
   the whole guarantee, and it needs nothing of the model (no monotonicity, no
   continuity). Narrower bands are found when a sample happens to fall in them.
2. **Refine.** Every pair of neighbouring samples whose regimes differ is a bracket. All
   brackets are cut together into up to ``sections`` equal parts per pass (one batch per
   pass), each keeping the sub-brackets whose ends differ, until all are no wider than
   the tolerance. A band hidden inside a bracket and revealed by a cut becomes brackets
   of its own, so the final brackets chain: each one's upper regime is the next one's
   lower regime. With 16 parts a 1 m/s bracket reaches 0.01 m/s in two passes.

Per-pass batches are small, and a batch costs about as much per step as its slowest
scene: many cuts per pass make few passes, which is what costs.

Every input ends: a tolerance below :data:`RELATIVE_FLOOR` of the largest position is
refused before anything is evaluated (cuts closer than a few ulps would coincide and a
bracket would never shrink), each pass at least halves every bracket it cuts, and a
pass that leaves a bracket as wide as it was, or more than :data:`MAX_PASSES` passes, is
an error rather than a loop.
"""

from __future__ import annotations

import math
from collections.abc import Callable
from typing import NoReturn

import attrs
import numpy as np

from ..base.errors import ParameterError

#: Parts a bracket is cut into per pass.
SECTIONS = 16
#: The finest tolerance, relative to the largest |position| of the lines: 1e-13 is about
#: 450 ulps of a double, so the up to SECTIONS parts of a bracket that wide are each some
#: 28 ulps and distinct, and it is the tightest rtol the integrators take (a boundary
#: finer than that is below what the integration itself resolves).
RELATIVE_FLOOR = 1e-13
#: The most scan samples located together (a group of lines): what the finder holds,
#: some 40 bytes a sample, stays under 40 MB however many lines a request has.
GROUP_SCENES = 1_000_000
#: Passes never needed when the floor holds: each halves a bracket at least, and
#: span / tolerance <= 2 / RELATIVE_FLOOR < 2**45.
MAX_PASSES = 64

Evaluate = Callable[[np.ndarray, np.ndarray], np.ndarray]


@attrs.frozen(eq=False)
class Located:
    """Brackets of regime changes, sorted by line then position (arrays, one entry per
    boundary); ``first`` is each line's regime at its start. ``scenes``: how many the
    finder ran; ``passes``: refinement passes."""

    line: np.ndarray
    low: np.ndarray
    high: np.ndarray
    below: np.ndarray
    above: np.ndarray
    first: np.ndarray
    scenes: int
    passes: int


def _ragged(counts: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """For groups of ``counts`` items: each item's group and its index within the group."""
    group = np.repeat(np.arange(counts.size), counts)
    starts = np.cumsum(counts) - counts
    return group, np.arange(counts.sum()) - starts[group]


def scan_intervals(starts: np.ndarray, ends: np.ndarray, resolution: float) -> np.ndarray:
    """How many intervals each line's scan has (its samples are one more)."""
    # the 1e-12 keeps a span that is an exact multiple of the resolution from gaining a
    # needless interval to rounding
    return np.maximum(np.ceil((ends - starts) / resolution * (1.0 - 1e-12)), 1).astype(np.int64)


def scan_points(
    starts: np.ndarray, ends: np.ndarray, resolution: float
) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """The scan: each line's samples at equal spacing <= ``resolution``, both ends
    included. Returns (line of each sample, its index on the line, its position)."""
    span = ends - starts
    intervals = scan_intervals(starts, ends, resolution)
    line, k = _ragged(intervals + 1)
    x = starts[line] + span[line] * (k / intervals[line])
    last = k == intervals[line]
    x[last] = ends[line[last]]  # exactly the end, whatever the rounding
    return line, k, x


def _changes(
    line: np.ndarray, x: np.ndarray, codes: np.ndarray
) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
    """Brackets between neighbours of one line (``line`` sorted) whose codes differ."""
    at = np.flatnonzero((codes[:-1] != codes[1:]) & (line[:-1] == line[1:]))
    return line[at], x[at], x[at + 1], codes[at], codes[at + 1]


def finest_tolerance(starts: np.ndarray, ends: np.ndarray) -> float:
    """The finest tolerance :func:`locate` takes on lines [starts, ends]:
    RELATIVE_FLOOR of their largest |position| (same unit)."""
    largest = float(np.max(np.abs(np.concatenate([starts, ends])), initial=0.0))
    return RELATIVE_FLOOR * largest if largest > 0.0 else RELATIVE_FLOOR


def _stalled(tolerance: float, where: str) -> NoReturn:
    raise ParameterError(
        "tolerance",
        f"the boundaries could not be bracketed to {tolerance:g} ({where}): the tolerance "
        "is too close to what a double resolves; use a coarser one",
    )


def locate(
    evaluate: Evaluate,
    starts: np.ndarray,
    ends: np.ndarray,
    resolution: float,
    tolerance: float,
    sections: int = SECTIONS,
) -> Located:
    """Every regime change along the lines [starts, ends], each bracketed to within
    ``tolerance`` (same unit as the positions); :class:`ParameterError` (``tolerance``)
    for a tolerance finer than ``finest_tolerance`` of the lines, before any
    evaluation, or if a pass fails to shrink a bracket. Lines whose scans hold more than
    GROUP_SCENES samples are located a group at a time (what is held grows with a
    group, not with the request); a single line may hold at most GROUP_SCENES."""
    floor = finest_tolerance(starts, ends)
    if not (math.isfinite(tolerance) and tolerance >= floor):
        raise ParameterError(
            "tolerance",
            f"tolerance must be at least {floor:.3g} ({RELATIVE_FLOOR:g} of the largest "
            f"position, what a double resolves there), got {tolerance:g}",
        )
    samples = scan_intervals(starts, ends, resolution) + 1
    if samples.size and samples.max() > GROUP_SCENES:
        raise ParameterError(
            "resolution",
            f"resolution {resolution:g} makes {int(samples.max()):,} samples on one line, "
            f"more than {GROUP_SCENES:,}: coarsen it or shorten the line",
        )
    # consecutive lines, each group's samples at most GROUP_SCENES
    bounds, total = [0], 0
    for i, n in enumerate(samples.tolist()):
        if total + n > GROUP_SCENES:
            bounds.append(i)
            total = 0
        total += n
    bounds.append(samples.size)
    parts = [
        _locate(
            _shifted(evaluate, lo), starts[lo:hi], ends[lo:hi], resolution, tolerance, sections
        )  # fmt: skip
        for lo, hi in zip(bounds[:-1], bounds[1:], strict=True)
    ]
    if len(parts) == 1:
        return parts[0]

    def joined(name: str) -> np.ndarray:
        return np.concatenate([getattr(part, name) for part in parts])

    line = np.concatenate([p.line + lo for p, lo in zip(parts, bounds[:-1], strict=True)])
    return Located(
        line, joined("low"), joined("high"), joined("below"), joined("above"),
        joined("first"), sum(p.scenes for p in parts), max(p.passes for p in parts),
    )  # fmt: skip


def _shifted(evaluate: Evaluate, first: int) -> Evaluate:
    """``evaluate`` for a group of lines that starts at line ``first``."""
    return lambda line, x: evaluate(line + first, x)


def _locate(
    evaluate: Evaluate,
    starts: np.ndarray,
    ends: np.ndarray,
    resolution: float,
    tolerance: float,
    sections: int,
) -> Located:
    """:func:`locate` on one group of lines."""
    line, k, x = scan_points(starts, ends, resolution)
    codes = np.asarray(evaluate(line, x), dtype=np.int64)
    scenes = x.size
    first = codes[k == 0]
    b_line, low, high, below, above = _changes(line, x, codes)
    passes = 0
    while True:
        width = high - low
        wide = width > tolerance
        if not wide.any():
            break
        passes += 1
        if passes > MAX_PASSES:
            _stalled(tolerance, f"after {MAX_PASSES} refinement passes")
        # cuts so that the parts are no wider than the tolerance, at most `sections`
        cuts = np.ceil(np.minimum(width[wide] / tolerance, sections)).astype(np.int64) - 1
        cuts = np.maximum(cuts, 1)
        group, i = _ragged(cuts + 2)  # each bracket's ends and its cuts, in order
        points = low[wide][group] + width[wide][group] * (i / (cuts[group] + 1))
        inner = (i > 0) & (i <= cuts[group])
        sequence = np.empty(points.size, dtype=np.int64)
        sequence[i == 0] = below[wide]
        sequence[i == cuts[group] + 1] = above[wide]
        points[i == cuts[group] + 1] = high[wide]
        sequence[inner] = evaluate(b_line[wide][group[inner]], points[inner])
        scenes += int(inner.sum())
        # changes within each bracket's own sequence (never across two brackets)
        n_bracket, n_low, n_high, n_below, n_above = _changes(group, points, sequence)
        n_line = b_line[wide][n_bracket]
        if np.any(n_high - n_low >= width[wide][n_bracket]):  # a cut that cut nothing
            _stalled(tolerance, f"in refinement pass {passes}: a bracket did not shrink")
        keep = ~wide
        b_line = np.concatenate([b_line[keep], n_line])
        low = np.concatenate([low[keep], n_low])
        high = np.concatenate([high[keep], n_high])
        below = np.concatenate([below[keep], n_below])
        above = np.concatenate([above[keep], n_above])
    order = np.lexsort((low, b_line))
    return Located(
        b_line[order], low[order], high[order], below[order], above[order], first, scenes, passes
    )
