"""The model's outcome bands along the lines of shot sets, for many candidate plates at
once (docs/calibration.md, "P* and α* from oblique shots").

Every line of every candidate runs in the same batches of :func:`plateimpact.limits.locate`
(a scan and its refinement passes): a batch costs about as much as its slowest scene's
steps, so twenty candidates cost about twice what one does.
"""

from __future__ import annotations

import math
import time
from collections.abc import Mapping, Sequence

import attrs
import numpy as np

from ..base.errors import ParameterError
from ..limits import locate, regime_codes
from ..limits.bracketing import GROUP_SCENES, RELATIVE_FLOOR, scan_intervals
from ..limits.chunked import run_chunked
from ..model.batch import SceneBatch
from ..model.bodies import Plate, Sphere
from ..model.results import Outcome
from ..model.scene import IMPACT_SPEED
from ..run.simulation import Simulation
from .outcome_model import Bands, ShotLines

#: The finder's tolerance [m/s]: from RELATIVE_FLOOR of the fastest speed a line can
#: reach (what a double resolves there: limits.bracketing) to 10 m/s; its resolution [m/s]
#: from the tolerance to 100 m/s.
TOLERANCE_RANGE = (RELATIVE_FLOOR * IMPACT_SPEED.range.high, 10.0)
MAX_RESOLUTION = 100.0
#: The scenes a fit runs without being asked to run more (as a sweep, the limits and
#: validate): about a minute and a half of scenes in one batch, several minutes in a
#: fit's many small batches (docs/calibration.md).
MAX_FIT_SCENES = 1_000_000

__all__ = ["GROUP_SCENES", "MAX_FIT_SCENES", "Cost", "LineModel", "check_finder", "scan_scenes"]


def scan_scenes(shots: ShotLines, resolution: float) -> int:
    """The scan samples of the lines of one shot set, for one candidate [finder
    resolution in m/s]."""
    return int((scan_intervals(shots.start, shots.end, resolution) + 1).sum())


def check_finder(resolution: float, tolerance: float) -> None:
    """:class:`ParameterError` (``tolerance`` or ``resolution``) unless the finder's
    settings [m/s] are in their ranges: checked before any scene runs."""
    low, high = TOLERANCE_RANGE
    if not (math.isfinite(tolerance) and low <= tolerance <= high):
        raise ParameterError(
            "tolerance",
            f"tolerance must be in [{low:g}, {high:g}] m/s (from {RELATIVE_FLOOR:g} of the "
            f"fastest speed, about what a double resolves there), got {tolerance:g}",
        )
    if not (math.isfinite(resolution) and tolerance <= resolution <= MAX_RESOLUTION):
        raise ParameterError(
            "resolution",
            f"resolution must be in [{tolerance:g}, {MAX_RESOLUTION:g}] m/s (from the "
            f"tolerance), got {resolution:g}",
        )


@attrs.frozen
class Cost:
    """What the model runs took: candidate shot sets evaluated, scene batches, seconds."""

    evaluations: int = 0
    batches: int = 0
    seconds: float = 0.0


class LineModel:
    """The bands of shot-set lines for candidate plate constants.

    ``plate`` gives every constant the candidates do not replace; ``sphere`` is a
    placeholder for the batch's columns (each line has its own radius and mass);
    ``resolution`` and ``tolerance`` [m/s] are the finder's (docs/limits.md).
    """

    def __init__(
        self,
        simulation: Simulation,
        sphere: Sphere,
        plate: Plate,
        resolution: float,
        tolerance: float,
    ) -> None:
        check_finder(resolution, tolerance)
        self.simulation, self.sphere, self.plate = simulation, sphere, plate
        self.resolution, self.tolerance = resolution, tolerance
        self.cost = Cost()

    def bands(
        self, sets: Sequence[ShotLines], constants: Sequence[Mapping[str, float]]
    ) -> list[list[Bands]]:
        """For each pair of a shot set and plate constants [SI] (replacing the plate's),
        the bands of each of the set's lines, all found in the same batches. Scenes run
        RUN_CHUNK at a time; the perforating samples are kept only for the lines of sets
        with residual speeds (the only ones their likelihood reads)."""
        began = time.perf_counter()
        owner = np.concatenate([np.full(s.lines, k) for k, s in enumerate(sets)])
        obliquity = np.concatenate([s.obliquity for s in sets])
        radius = np.concatenate([s.radius for s in sets])
        mass = np.concatenate([s.mass for s in sets])
        residuals = np.array([bool(np.isfinite(s.residual).any()) for s in sets])[owner]
        replaced = {name: np.array([c[name] for c in constants])[owner] for name in constants[0]}
        base = SceneBatch.grid(self.sphere, self.plate, [1.0], [0.0])
        samples: list[tuple[np.ndarray, ...]] = []
        calls = [0]

        def evaluate(line: np.ndarray, x: np.ndarray) -> np.ndarray:
            def batch_of(index: np.ndarray) -> SceneBatch:
                on = line[index]
                return base.take(np.zeros(index.size, dtype=np.int64)).with_columns(
                    impact_speed=x[index],
                    impact_obliquity=obliquity[on],
                    radius=radius[on],
                    mass=mass[on],
                    **{name: values[on] for name, values in replaced.items()},
                )

            codes = np.empty(x.size, dtype=np.int64)
            for where, result in run_chunked(self.simulation, batch_of, x.size):
                codes[where] = regime_codes(result)
                on, found = line[where], codes[where] // 2
                keep = residuals[on] & (found == Outcome.PERFORATION)
                if keep.any():
                    speed = np.asarray(result.exit_speed)[keep]
                    samples.append((on[keep], x[where][keep], found[keep], speed))
            calls[0] += 1
            return codes

        starts = np.concatenate([s.start for s in sets])
        ends = np.concatenate([s.end for s in sets])
        found = locate(evaluate, starts, ends, self.resolution, self.tolerance)
        kept = [np.concatenate(c) for c in zip(*samples, strict=True)] or [np.zeros(0)] * 4
        order = np.argsort(kept[0], kind="stable")  # by line, each line's in run order
        line, x, outcome, exit_speed = (c[order] for c in kept)
        lines = np.arange(owner.size + 1)
        at_sample, at_found = np.searchsorted(line, lines), np.searchsorted(found.line, lines)
        out: list[list[Bands]] = [[] for _ in sets]
        for index in range(owner.size):
            mine = slice(at_found[index], at_found[index + 1])
            at = 0.5 * (found.low[mine] + found.high[mine])
            outcomes = np.concatenate([[found.first[index] // 2], found.above[mine] // 2])
            # a change of the plate's state alone (ricochet, then ricochet after failure)
            # is no boundary of outcomes
            change = outcomes[1:] != outcomes[:-1]
            outcomes = np.concatenate([outcomes[:1], outcomes[1:][change]])
            edges = np.concatenate([[-np.inf], at[change], [np.inf]])
            on_line = slice(at_sample[index], at_sample[index + 1])
            out[owner[index]].append(
                _bands(edges, outcomes, x[on_line], outcome[on_line], exit_speed[on_line])
            )
        self.cost = Cost(
            self.cost.evaluations + len(sets),
            self.cost.batches + calls[0],
            self.cost.seconds + time.perf_counter() - began,
        )
        return out


def _bands(
    edges: np.ndarray, outcomes: np.ndarray, x: np.ndarray, outcome: np.ndarray, g: np.ndarray
) -> Bands:
    """The bands of one line, with the samples of its last run of perforation."""
    perforation = outcomes == Outcome.PERFORATION
    if not perforation[-1]:
        return Bands(edges, outcomes, np.zeros(0), np.zeros(0), math.nan)
    k = outcomes.size - 1
    while k > 0 and perforation[k - 1]:
        k -= 1
    limit = float(edges[k])
    keep = (outcome == Outcome.PERFORATION) & (x >= limit)
    order = np.argsort(x[keep], kind="stable")
    return Bands(edges, outcomes, x[keep][order], g[keep][order], limit)
