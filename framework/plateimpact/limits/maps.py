"""The outcome map: the (impact speed, obliquity) plane on a grid, with every boundary
located along each row of the grid.

The grid is the finder's scan (limits.bracketing): one row per obliquity, the speeds equally
spaced, so the map costs one batch of rows × speeds scenes and the refinement passes of
its boundaries. Its resolution is the grid's spacing: a band narrower than that may be
missing from a row (``plateimpact limits`` finds every band of 1 m/s).
"""

from __future__ import annotations

import math
from collections.abc import Iterable, Sequence
from concurrent.futures import Executor
from typing import TYPE_CHECKING

import attrs
import numpy as np

from ..base.errors import ParameterError
from ..base.parameters import check_instance
from ..model.bodies import Plate, Sphere
from ..model.results import BatchResult
from ..model.scene import IMPACT_OBLIQUITY, IMPACT_SPEED
from ..run.simulation import Simulation
from . import views
from .bracketing import RELATIVE_FLOOR, finest_tolerance, scan_points
from .lines import SPEED
from .plate_limits import (
    SPEED_RANGE,
    SPEED_TOLERANCE,
    Limits,
    _find,
    _floats,
    _interval,
    check_steps,
)
from .regimes import Regime, regime_codes

if TYPE_CHECKING:
    import pandas
    import xarray

#: The default grid: 200 speeds over 50-2000 m/s, 86 obliquities 0-85 deg.
MAP_SPEED_SAMPLES = 200
MAP_OBLIQUITIES = np.radians(np.arange(0.0, 86.0))
#: The largest map, as a sweep's largest grid.
MAX_MAP_SCENES = 1_000_000


@attrs.frozen(eq=False, repr=False)
class OutcomeMap:
    """Regimes and exit states on a grid of impact ``speeds`` [m/s] (columns) and
    ``obliquities`` [rad] (rows): ``regime`` (an :class:`~plateimpact.Outcome` per
    cell), ``exit_speed`` [m/s] and ``exit_obliquity`` [rad]; and ``limits``: the bands
    along each row, boundaries located to ``limits.tolerance`` with the grid's spacing
    as resolution."""

    speeds: np.ndarray
    obliquities: np.ndarray
    regime: np.ndarray
    exit_speed: np.ndarray
    exit_obliquity: np.ndarray
    limits: Limits

    @property
    def shape(self) -> tuple[int, int]:
        """(obliquities, speeds)."""
        return self.regime.shape

    def to_xarray(self) -> xarray.Dataset:
        """The grid as an xarray Dataset over (``impact_obliquity`` [rad],
        ``impact_speed`` [m/s]): each cell's ``outcome`` and ``plate_failed`` (CF flags),
        ``exit_speed`` [m/s] and ``exit_obliquity`` [rad]; what produced it as
        attributes."""
        return views.map_table(self).to_xarray()

    def to_dataframe(self) -> pandas.DataFrame:
        """The grid, one row per cell (index ``impact_obliquity_deg``,
        ``impact_speed_m_s``), in user units with the unit in each column's name. pandas
        is needed (``pip install 'plateimpact[review]'``)."""
        return views.map_table(self).to_dataframe()

    def __repr__(self) -> str:
        return views.map_repr(self)

    def _repr_html_(self) -> str:
        return views.map_html(self)

    def boundary_curves(self) -> list[tuple[Regime, Regime, np.ndarray, np.ndarray]]:
        """The boundaries as curves: (below, above, speeds [m/s], obliquities [rad]),
        joining a row's boundary to the nearest one between the same regimes on the next
        row (a curve ends on the first row without such a boundary)."""
        open_curves: list[tuple[Regime, Regime, list[float], list[float], int]] = []
        done: list[tuple[Regime, Regime, list[float], list[float], int]] = []
        for row, line in enumerate(self.limits.lines):
            still_open = []
            taken: set[int] = set()
            for boundary in line.boundaries:
                best, gap = None, math.inf
                for k, (below, above, xs, _, last) in enumerate(open_curves):
                    if (
                        k in taken
                        or last != row - 1
                        or (below, above)
                        != (
                            boundary.below,
                            boundary.above,
                        )
                    ):
                        continue
                    if abs(xs[-1] - boundary.at) < gap:
                        best, gap = k, abs(xs[-1] - boundary.at)
                if best is None:
                    still_open.append((boundary.below, boundary.above, [boundary.at],
                                       [line.fixed], row))  # fmt: skip
                else:
                    taken.add(best)
                    below, above, xs, ys, _ = open_curves[best]
                    xs.append(boundary.at)
                    ys.append(line.fixed)
                    still_open.append((below, above, xs, ys, row))
            done += [curve for k, curve in enumerate(open_curves) if k not in taken]
            open_curves = still_open
        return [(b, a, np.array(xs), np.array(ys)) for b, a, xs, ys, _ in done + open_curves]


def outcome_map(
    simulation: Simulation,
    sphere: Sphere,
    plate: Plate,
    speeds: tuple[float, float] = SPEED_RANGE,
    speed_samples: int = MAP_SPEED_SAMPLES,
    obliquities: Iterable[float] = MAP_OBLIQUITIES,
    *,
    tolerance: float = SPEED_TOLERANCE,
    executor: Executor | None = None,
) -> OutcomeMap:
    """The outcome map of ``plate`` over ``speed_samples`` equally spaced speeds in
    ``speeds`` (start, stop) [m/s] and each of ``obliquities`` [rad]; boundaries to
    ``tolerance`` [m/s]."""
    check_instance("plate", plate, Plate)
    (found,) = outcome_maps(
        simulation, sphere, [plate], speeds, speed_samples, obliquities,
        tolerance=tolerance, executor=executor,
    )  # fmt: skip
    return found


def outcome_maps(
    simulation: Simulation,
    sphere: Sphere,
    plates: Sequence[Plate],
    speeds: tuple[float, float] = SPEED_RANGE,
    speed_samples: int = MAP_SPEED_SAMPLES,
    obliquities: Iterable[float] = MAP_OBLIQUITIES,
    *,
    tolerance: float = SPEED_TOLERANCE,
    executor: Executor | None = None,
) -> list[OutcomeMap]:
    """The outcome maps of several plates on one grid (``speeds`` (start, stop) [m/s],
    ``speed_samples`` of them, ``obliquities`` [rad], boundaries to ``tolerance`` [m/s],
    as :func:`outcome_map`), found together: their rows share
    the batches, and so the refinement passes, which cost more than their scenes (five
    plates take about three times as long as one). The plates must declare the same
    constants."""
    rows = _floats("obliquities", obliquities)
    IMPACT_OBLIQUITY.check(rows)
    if not np.all(np.diff(rows) > 0):
        raise ParameterError("obliquities", "the map's obliquities must increase")
    span = _interval("speeds", speeds, IMPACT_SPEED)
    if not (isinstance(speed_samples, int | np.integer) and speed_samples >= 2):
        raise ParameterError(
            "speed_samples", f"a map needs at least 2 speeds, got {speed_samples!r}"
        )
    plates = list(plates)
    scenes = len(plates) * rows.size * speed_samples
    if not plates or scenes > MAX_MAP_SCENES:
        raise ParameterError(
            "speed_samples",
            f"{len(plates)} map(s) of {rows.size} x {speed_samples} make {scenes:,} scenes; "
            f"give at least one plate and at most {MAX_MAP_SCENES:,} scenes",
        )
    resolution = (span[1] - span[0]) / (speed_samples - 1)
    floor = finest_tolerance(np.array([span[0]]), np.array([span[1]]))
    if not (math.isfinite(tolerance) and floor <= tolerance <= resolution):
        raise ParameterError(
            "tolerance",
            f"tolerance must be in [{floor:.3g}, {resolution:g}] m/s (from {RELATIVE_FLOOR:g} "
            f"of the fastest speed to the map's spacing), got {tolerance:g}",
        )
    check_steps(tolerance, resolution, span, rows.size, "m/s", 1.0)
    scans: list[BatchResult] = []
    found = _find(
        simulation, sphere, plates, SPEED, rows, span, tolerance, resolution, executor, scans
    )
    (scan,) = scans
    _, _, x = scan_points(np.full(rows.size, span[0]), np.full(rows.size, span[1]), resolution)
    assert x.size == rows.size * speed_samples  # the scan is the grid, row by row
    shape = (len(plates), rows.size, speed_samples)
    regime = regime_codes(scan).reshape(shape)
    exit_speed = np.asarray(scan.exit_speed).reshape(shape)
    exit_obliquity = np.asarray(scan.exit_obliquity).reshape(shape)
    return [
        OutcomeMap(
            speeds=x[:speed_samples].copy(),
            obliquities=rows,
            regime=regime[k],
            exit_speed=exit_speed[k],
            exit_obliquity=exit_obliquity[k],
            limits=limits,
        )
        for k, limits in enumerate(found)
    ]
