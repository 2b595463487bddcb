"""The limits of a plate: every outcome band along lines of the (speed, obliquity) plane.

``along_speed`` sweeps impact speed at fixed obliquities (ballistic and ricochet
limits); ``along_obliquity`` sweeps obliquity at fixed speeds (the critical ricochet
obliquity). Both run any simulation, all lines in one batch per pass (limits.bracketing).
"""

from __future__ import annotations

import math
import time
from collections.abc import Iterable, Sequence
from concurrent.futures import Executor
from typing import TYPE_CHECKING, Any

import attrs
import numpy as np

from ..base.errors import ParameterError, PluginError, WorkBoundError
from ..base.parameters import check_instance
from ..model.batch import SceneBatch
from ..model.bodies import MASS, RADIUS, Plate, Sphere
from ..model.results import BatchResult
from ..model.scene import IMPACT_OBLIQUITY, IMPACT_SPEED
from ..provenance.code import limits_record, plugins_record
from ..provenance.metadata import source_commit, versions
from ..registry.plugin_registry import PluginRegistry
from ..run.simulation import Simulation
from ..storage.plate_file import plate_to_dict
from . import views
from .bracketing import (
    GROUP_SCENES,
    RELATIVE_FLOOR,
    SECTIONS,
    Located,
    finest_tolerance,
    locate,
)
from .chunked import run_chunked
from .lines import OBLIQUITY, SPEED, Boundary, LimitLine, unit_suffix
from .regimes import Regime, regime_codes

if TYPE_CHECKING:
    import pandas
    import xarray

_DEG = math.pi / 180.0
#: Defaults: boundaries to 0.01 m/s or 0.001 deg; no band of 1 m/s or 0.1 deg missed.
SPEED_TOLERANCE, SPEED_RESOLUTION = 0.01, 1.0  # [m/s]
OBLIQUITY_TOLERANCE, OBLIQUITY_RESOLUTION = 0.001 * _DEG, 0.1 * _DEG  # [rad]
#: The default lines: 50-2000 m/s; 0-89 deg.
SPEED_RANGE = (50.0, 2000.0)  # [m/s]
OBLIQUITY_RANGE = (0.0, 89.0 * _DEG)  # [rad]
#: The scan's largest batch, as a sweep's: more belongs in a study.
MAX_SCAN_SCENES = 1_000_000


@attrs.frozen(eq=False, repr=False)
class Limits:
    """The bands of every line of one request, with what produced them.

    ``axis`` is ``impact_speed`` or ``impact_obliquity``; ``tolerance`` and
    ``resolution`` are in its SI unit (m/s or rad); ``model`` is the simulation's
    plug-ins and settings; ``scenes`` how many scenes the finder ran, ``passes`` its
    refinement passes, ``seconds`` the wall time (for plates found together, the
    request's: see :func:`~plateimpact.limits.outcome_maps`); ``plugins`` the code
    that found them (provenance.code; None if read from a record made before
    it was recorded).
    """

    axis: str
    lines: tuple[LimitLine, ...]
    tolerance: float
    resolution: float
    sphere: Sphere
    plate: Plate
    model: dict[str, Any]
    scenes: int
    passes: int
    seconds: float
    plugins: dict[str, Any] | None = None
    #: The plug-ins of the simulation that found them: the declarations of the plate's
    #: constants (None when read back without one: then no plate record can be written).
    registry: PluginRegistry | None = attrs.field(default=None, kw_only=True, repr=False)

    def plate_record(self) -> dict[str, Any]:
        """The plate as a plate file holds it (storage.plate_file), without its format."""
        if self.registry is None:
            raise PluginError(
                "these limits carry no plug-in registry to describe their plate with: read "
                "them with read_limits(..., registry=...)"
            )
        record = plate_to_dict(self.plate, registry=self.registry)
        return {k: v for k, v in record.items() if k != "format"}

    def to_xarray(self) -> xarray.Dataset:
        """The named limits of every line as an xarray Dataset over the lines' fixed
        coordinate (``impact_obliquity`` [rad] along speed, ``impact_speed`` [m/s] along
        obliquity) [SI, CF ``units``; NaN: none on the line], with the plate, sphere,
        model and tolerance as attributes."""
        return views.limits_table(self).to_xarray()

    def to_dataframe(self) -> pandas.DataFrame:
        """The named limits of every line, one row per line, in user units with the unit
        in each column's name (``ballistic_limit_m_s``, index ``impact_obliquity_deg``).
        pandas is needed (``pip install 'plateimpact[review]'``)."""
        return views.limits_table(self).to_dataframe()

    def __repr__(self) -> str:
        return views.limits_repr(self)

    def _repr_html_(self) -> str:
        return views.limits_html(self)

    def to_json(self) -> dict[str, Any]:
        """One object in user units (``plateimpact limits --json``)."""
        unit = unit_suffix(self.axis)
        scale = _DEG if self.axis == OBLIQUITY else 1.0
        return {
            "plate": self.plate_record(),
            "sphere": {
                RADIUS.key: self.sphere.radius / RADIUS.scale,
                MASS.key: self.sphere.mass / MASS.scale,
            },
            "model": self.model,
            "axis": self.axis,
            f"tolerance_{unit}": self.tolerance / scale,
            f"resolution_{unit}": self.resolution / scale,
            "lines": [line.to_json() for line in self.lines],
            "scenes": self.scenes,
            "versions": versions(),
            "source_commit": source_commit(),
            "plugins": self.plugins,
        }


def _floats(name: str, values: Iterable[float] | float) -> np.ndarray:
    try:
        array = np.atleast_1d(np.asarray(values, dtype=float)).reshape(-1)
    except (TypeError, ValueError):
        raise ParameterError(name, f"{name} must be numbers, got {values!r:.80}") from None
    if array.size == 0:
        raise ParameterError(name, f"{name}: give at least one value")
    return array


def _interval(name: str, values: tuple[float, float], declared: Any) -> tuple[float, float]:
    bounds = _floats(name, values)
    if bounds.size != 2:
        raise ParameterError(name, f"{name} must be a range (start, stop), got {values!r:.80}")
    declared.check(bounds)
    start, stop = float(bounds[0]), float(bounds[1])
    if not start < stop:
        raise ParameterError(
            name,
            f"the range is empty (start {declared.format(start)} must be below "
            f"stop {declared.format(stop)} {declared.user_unit})",
        )
    return start, stop


def check_steps(
    tolerance: float,
    resolution: float,
    span: tuple[float, float],
    lines: int,
    unit: str,
    scale: float,
    max_scenes: int | None = MAX_SCAN_SCENES,
) -> None:
    """Tolerance in [RELATIVE_FLOOR of the range's largest value, the range's width];
    resolution in [tolerance, the width]; a scan of at most GROUP_SCENES samples a line
    and ``max_scenes`` (None: any number) in all. The floor is what a double resolves
    there: finer cuts would coincide (limits.bracketing)."""
    width = span[1] - span[0]
    shown = f"{width / scale:.6g} {unit}"
    floor = finest_tolerance(np.array([span[0]]), np.array([span[1]]))
    if not (math.isfinite(tolerance) and floor <= tolerance <= width):
        raise ParameterError(
            "tolerance",
            f"tolerance must be in [{floor / scale:.3g}, {width / scale:.6g}] {unit} (from "
            f"{RELATIVE_FLOOR:g} of "
            f"the range's largest value, about what a double resolves there, to the range), "
            f"got {tolerance / scale:g}",
        )
    if not (math.isfinite(resolution) and tolerance <= resolution <= width):
        raise ParameterError(
            "resolution",
            f"resolution must be in [{tolerance / scale:g}, {width / scale:.6g}] {unit} (from "
            f"the tolerance to the range), got {resolution / scale:g}",
        )
    per_line = math.ceil(width / resolution) + 1
    if per_line > GROUP_SCENES:
        raise ParameterError(
            "resolution",
            f"resolution {resolution / scale:g} {unit} over {shown} makes {per_line:,} "
            f"samples a line, more than {GROUP_SCENES:,} (no override: coarsen it or "
            "shorten the range)",
        )
    scan = lines * per_line
    if max_scenes is not None and scan > max_scenes:
        raise WorkBoundError(
            "resolution",
            f"resolution {resolution / scale:g} {unit} over {lines:,} line(s) of {shown} "
            f"needs {scan:,} scenes, more than {max_scenes:,}: coarsen it, ask for fewer "
            "lines or a shorter range, or lift the bound (max_scenes=None; --force)",
        )


def line_of(
    found: Located, index: int, axis: str, fixed: float, span: tuple[float, float]
) -> LimitLine:
    """Line ``index`` of what :func:`~.bracketing.locate` found, as a :class:`LimitLine`
    along ``axis`` over ``span`` at the other coordinate ``fixed``."""
    # the brackets are sorted by line: a line's are one slice (found in log time, so
    # that reading every line of a many-line search costs no more than the lines)
    start, stop = np.searchsorted(found.line, [index, index + 1])
    mine = slice(int(start), int(stop))
    boundaries = tuple(
        Boundary(float(lo), float(hi), Regime.of_code(b), Regime.of_code(a))
        for lo, hi, b, a in zip(
            found.low[mine], found.high[mine], found.below[mine], found.above[mine],
            strict=True,
        )
    )  # fmt: skip
    first = Regime.of_code(int(found.first[index]))
    return LimitLine(axis, fixed, span[0], span[1], boundaries, first)


def _find(
    simulation: Simulation,
    sphere: Sphere,
    plates: Sequence[Plate],
    axis: str,
    fixed: np.ndarray,
    span: tuple[float, float],
    tolerance: float,
    resolution: float,
    executor: Executor | None,
    scans: list[BatchResult] | None = None,
) -> list[Limits]:
    """The limits of each of ``plates`` along lines ``axis`` at each of ``fixed``, all
    plates' lines in the same batches (so they share the refinement passes, which cost
    more than their scenes). ``scans``, if given, receives the scan's results (the first
    batch: every line's samples, plate-major, then line-major), which maps draw."""
    check_instance("simulation", simulation, Simulation)
    # one scene per plate (which checks sphere and plates); the plates must declare the
    # same constants to share a batch
    base = SceneBatch.concat([SceneBatch.grid(sphere, plate, [1.0], [0.0]) for plate in plates])
    plate_of_line = np.repeat(np.arange(len(plates)), fixed.size)
    fixed_of_line = np.tile(fixed, len(plates))

    def evaluate(line: np.ndarray, x: np.ndarray) -> np.ndarray:
        def batch_of(index: np.ndarray) -> SceneBatch:
            on, at = line[index], x[index]
            speed, obliquity = (at, fixed_of_line[on]) if axis == SPEED else (fixed_of_line[on], at)
            return base.take(plate_of_line[on]).with_columns(
                impact_speed=speed, impact_obliquity=obliquity
            )

        codes = np.empty(x.size, dtype=np.int64)
        keep = scans is not None and not scans  # the scan's results, for a map
        kept = []
        for where, result in run_chunked(simulation, batch_of, x.size, executor):
            codes[where] = regime_codes(result)
            if keep:
                kept.append(result)
        if scans is not None and keep:
            scans.append(BatchResult.concat(kept))
        return codes

    began = time.perf_counter()
    starts, ends = np.full(fixed_of_line.size, span[0]), np.full(fixed_of_line.size, span[1])
    found = locate(evaluate, starts, ends, resolution, tolerance, SECTIONS)
    seconds = time.perf_counter() - began
    lines = [line_of(found, i, axis, float(value), span) for i, value in enumerate(fixed_of_line)]
    model = simulation.describe()
    plugins = {**plugins_record(simulation), "limits": limits_record()}
    n = fixed.size
    return [
        Limits(
            axis,
            tuple(lines[k * n : (k + 1) * n]),
            tolerance,
            resolution,
            sphere,
            plate,
            model,
            found.scenes,
            found.passes,
            seconds,
            plugins,
            registry=simulation.registry,
        )  # fmt: skip
        for k, plate in enumerate(plates)
    ]


def along_speed(
    simulation: Simulation,
    sphere: Sphere,
    plate: Plate,
    obliquities: Iterable[float] | float,
    speeds: tuple[float, float] = SPEED_RANGE,
    *,
    tolerance: float = SPEED_TOLERANCE,
    resolution: float = SPEED_RESOLUTION,
    executor: Executor | None = None,
    max_scenes: int | None = MAX_SCAN_SCENES,
) -> Limits:
    """The outcome bands along impact speed at each of ``obliquities`` [rad].

    ``speeds`` is the range (start, stop) [m/s]. Every boundary is bracketed to within
    ``tolerance`` [m/s], and no band ``resolution`` [m/s] wide or wider is missed
    (docs/limits.md). ``executor`` (a process pool) spreads the scan over workers.
    A scan of more than ``max_scenes`` scenes (None: no bound) is refused before any
    scene runs (:class:`~plateimpact.base.errors.WorkBoundError`).
    """
    fixed = _floats("obliquities", obliquities)
    IMPACT_OBLIQUITY.check(fixed)
    span = _interval("speeds", speeds, IMPACT_SPEED)
    check_steps(tolerance, resolution, span, fixed.size, "m/s", 1.0, max_scenes)
    (found,) = _find(
        simulation, sphere, [plate], SPEED, fixed, span, tolerance, resolution, executor
    )
    return found


def along_obliquity(
    simulation: Simulation,
    sphere: Sphere,
    plate: Plate,
    speeds: Iterable[float] | float,
    obliquities: tuple[float, float] = OBLIQUITY_RANGE,
    *,
    tolerance: float = OBLIQUITY_TOLERANCE,
    resolution: float = OBLIQUITY_RESOLUTION,
    executor: Executor | None = None,
    max_scenes: int | None = MAX_SCAN_SCENES,
) -> Limits:
    """The outcome bands along impact obliquity at each of ``speeds`` [m/s].

    ``obliquities`` is the range (start, stop) [rad], within [0, π/2); ``tolerance`` and
    ``resolution`` [rad] and ``max_scenes`` as for :func:`along_speed`.
    """
    fixed = _floats("speeds", speeds)
    IMPACT_SPEED.check(fixed)
    span = _interval("obliquities", obliquities, IMPACT_OBLIQUITY)
    check_steps(tolerance, resolution, span, fixed.size, "deg", _DEG, max_scenes)
    (found,) = _find(
        simulation, sphere, [plate], OBLIQUITY, fixed, span, tolerance, resolution, executor
    )
    return found
