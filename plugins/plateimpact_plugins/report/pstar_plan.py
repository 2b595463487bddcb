"""A P* fit checked, and its work estimated, before any scene runs (docs/calibration.md,
"P* and α* from oblique shots", and docs/robustness.md, "The input domain and the work
bounds").

What the shots can say is known before the model runs: a shot set with fewer shots than
a fit needs, or whose shots all allow one outcome in common (all ricochets, all
perforated, ...) with no residual speed to fit, bounds P* from one side at best, so the
likelihood cannot be peaked. Such sets are refused (or, by obliquity, left to the other
range) at once, all of them in one line, instead of after the scan.

The work is the model's boundaries along every line of every set, for every candidate P*
the search tries: the scan's samples of a candidate (known from the shots' speeds and the
finder's resolution) times the candidates. A fit whose estimate exceeds ``max_scenes``
is refused before any scene runs, naming the bound and how to lift it.
"""

from __future__ import annotations

from collections.abc import Sequence

import numpy as np

from plateimpact import Outcome, WorkBoundError, calibration

from .pstar_search import ALPHA_FIT_EVALUATIONS, SCAN_POINTS, ShotLines, scan_scenes

#: The scenes a fit runs without being asked to run more: the core's bound.
MAX_FIT_SCENES = calibration.MAX_FIT_SCENES
#: Candidates a set costs after its scan: the bracketing search (Chandrupatla, from a
#: bracket of two scan steps to 0.1 % of P*: 5 to 7 measured) and the information's two
#: points, with room.
SEARCH_EVALUATIONS = 10
#: With α*: Nelder–Mead's evaluations at most, and two nine-point information stencils.
ALPHA_EVALUATIONS = ALPHA_FIT_EVALUATIONS + 18


def unfittable(lines: ShotLines | None, shots: int, least: int) -> str | None:
    """Why a shot set cannot fix P*, when that is plain from the shots alone: fewer than
    ``least``, or every shot allows one outcome in common and none adds a residual speed
    (the likelihood then has its maximum wherever that outcome covers every shot: a bound
    from one side, never a peak). None if the set may fix P*."""
    if lines is None or shots < least:
        return f"{shots} shots, at least {least} needed"
    common = int(np.bitwise_and.reduce(lines.allowed))
    if common and not np.isfinite(lines.residual).any():
        said = " or ".join(o.label for o in Outcome if common >> int(o) & 1)
        return (
            f"every one of its {shots} shots allows {said}, so they bound P* from one side "
            "only; shots on both sides of a boundary are needed"
        )
    return None


def estimate_scenes(sets: Sequence[ShotLines], resolution: float, fit_alpha: bool) -> int:
    """About how many scenes a fit of ``sets`` runs: each set's scan samples for one
    candidate [finder resolution in m/s] times the candidates it tries."""
    per_candidate = sum(scan_scenes(shots, resolution) for shots in sets)
    candidates = SCAN_POINTS + SEARCH_EVALUATIONS + (ALPHA_EVALUATIONS if fit_alpha else 0)
    return per_candidate * candidates


def check_work(
    what: str,
    sets: Sequence[ShotLines],
    resolution: float,
    fit_alpha: bool,
    max_scenes: int | None,
) -> None:
    """:class:`WorkBoundError` if the fit's estimate exceeds ``max_scenes`` (None: no
    bound)."""
    if max_scenes is None:
        return
    scenes = estimate_scenes(sets, resolution, fit_alpha)
    if scenes > max_scenes:
        lines = sum(shots.lines for shots in sets)
        raise WorkBoundError(
            "max_scenes",
            f"{what}: about {scenes:,} scenes ({len(sets):,} shot set(s) on {lines:,} "
            f"line(s), each candidate P* located along every line at the resolution "
            f"{resolution:g} m/s), more than {max_scenes:,}: coarsen the resolution, fit "
            "fewer obliquities or spheres at once, or lift the bound (max_scenes=None; "
            "--force)",
        )
