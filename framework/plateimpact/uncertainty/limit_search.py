"""The ballistic and ricochet limits of many sampled scenes at once: one line along
impact speed per (sample, obliquity), every line's scenes in the same batches of the
limits finder (limits.bracketing), so that all lines share its refinement passes.

Along a line, what ``plateimpact limits`` names (limits.lines.LimitLine):

* the **ballistic limit**: the lowest speed above which every speed of the range
  perforates; −inf where the whole range perforates, +inf where none of it does;
* the **ricochet limit**: the highest speed at which the sphere ricochets (off an intact
  or a failed plate); +inf where it still ricochets at the range's end, −inf where it
  ricochets at no speed of the range (at normal incidence it never does).

P(perforation | V) = P(V_bl < V) and P(ricochet | V) = P(V_rl > V) count a sample right
at every speed when it perforates exactly above its ballistic limit and ricochets exactly
below its ricochet limit; a sample with a band of the other kind on the wrong side (a
perforation band below a non-perforating one, or a ricochet band above a non-ricochet
one) is counted in ``perforation_gaps`` / ``ricochet_gaps``, so that a report can say so.
"""

from __future__ import annotations

import math
from concurrent.futures import Executor
from typing import Any

import attrs
import numpy as np

from ..limits.bracketing import locate
from ..limits.chunked import run_chunked
from ..limits.lines import SPEED, LimitLine
from ..limits.plate_limits import line_of
from ..limits.regimes import regime_codes
from ..model.batch import SceneBatch
from ..model.results import Outcome
from ..registry.plugin_registry import PluginRegistry
from ..run.simulation import Simulation
from .propagation import scenes
from .spec import UncertaintySpec

#: The defaults of a sampled limit: the speed range [m/s], each limit's bracket [m/s],
#: and the scan's step [m/s] (a band narrower than it may be missed: coarser than the
#: limits command's 1 m/s, since a limit is found for every sample).
SPEEDS, TOLERANCE, RESOLUTION = (50.0, 2000.0), 0.1, 20.0


@attrs.frozen(eq=False)
class LineLimits:
    """What the finder found along each line: the ballistic and ricochet limits [m/s]
    (±inf as the module says), whether each line has a gap (module docstring), and the
    scenes the finder ran and its refinement passes."""

    ballistic: np.ndarray
    ricochet: np.ndarray
    perforation_gaps: np.ndarray
    ricochet_gaps: np.ndarray
    scenes: int
    passes: int


def sample_scenes(
    spec: UncertaintySpec,
    values: dict[str, np.ndarray],
    registry: PluginRegistry,
    speeds: tuple[float, float],
) -> SceneBatch:
    """One scene per sample of ``values`` [user units] (the speed set to the range's
    start: each line sets its own)."""
    n = next(iter(values.values())).size if values else spec.samples
    nominal = attrs.evolve(spec, samples=n, at={**spec.at, "speed_m_s": speeds[0]})
    return scenes(nominal, values, registry)


def named_limits(line: LimitLine) -> tuple[float, float, bool, bool]:
    """(ballistic limit, ricochet limit, perforation gap, ricochet gap) of one line."""
    outcomes = [band.regime.outcome for band in line.bands]
    ballistic = line.ballistic_limit
    if ballistic is None:  # the top band perforates only if the whole line does
        ballistic = -math.inf if outcomes[-1] is Outcome.PERFORATION else math.inf
    ricochet = line.ricochet_limit
    if ricochet is None:  # a ricochet band reaches the end, or there is none
        ricochet = math.inf if Outcome.RICOCHET in outcomes else -math.inf
    top = len(outcomes)  # the final run of perforation starts at top
    while top and outcomes[top - 1] is Outcome.PERFORATION:
        top -= 1
    bottom = 0  # the first run of ricochet ends at bottom
    while bottom < len(outcomes) and outcomes[bottom] is Outcome.RICOCHET:
        bottom += 1
    perforation_gap = Outcome.PERFORATION in outcomes[:top]
    ricochet_gap = Outcome.RICOCHET in outcomes[bottom:]
    return ballistic, ricochet, perforation_gap, ricochet_gap


def line_limits(
    base: SceneBatch,
    sample_of_line: np.ndarray,
    obliquity_of_line: np.ndarray,
    simulation: Simulation,
    *,
    speeds: tuple[float, float] = SPEEDS,
    tolerance: float = TOLERANCE,
    resolution: float = RESOLUTION,
    executor: Executor | None = None,
) -> LineLimits:
    """The limits along one line of impact speed per entry of ``sample_of_line`` (the
    scene of ``base`` it runs) at ``obliquity_of_line`` [rad], over ``speeds`` [m/s];
    ``executor``: where the finder's batches run, in chunks (the same bits)."""

    def evaluate(line: np.ndarray, x: np.ndarray) -> np.ndarray:
        def batch_of(index: np.ndarray) -> Any:
            on = line[index]
            return base.take(sample_of_line[on]).with_columns(
                impact_speed=x[index], impact_obliquity=obliquity_of_line[on]
            )

        codes = np.empty(x.size, dtype=np.int64)
        for where, result in run_chunked(simulation, batch_of, x.size, executor):
            codes[where] = regime_codes(result)
        return codes

    n = sample_of_line.size
    found = locate(evaluate, np.full(n, speeds[0]), np.full(n, speeds[1]), resolution, tolerance)
    named = np.array(
        [
            named_limits(line_of(found, i, SPEED, float(obliquity_of_line[i]), speeds))
            for i in range(n)
        ],
        dtype=float,
    ).reshape(n, 4)
    return LineLimits(
        named[:, 0], named[:, 1], named[:, 2] > 0, named[:, 3] > 0, found.scenes, found.passes
    )
