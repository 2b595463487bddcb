"""The columns of a stored limits or outcome-map record (docs/archive.md, "Limits and
outcome maps"): what a :class:`Limits` or an :class:`OutcomeMap` holds as netCDF
variables over named dimensions, SI, each with CF ``units`` and ``long_name`` and the
regime codes with CF flags.

Limits run over ``line`` (one per fixed obliquity or speed: ``impact_obliquity(line)``
or ``impact_speed(line)``, an auxiliary coordinate) and ``boundary`` (each boundary's
line in ``boundary_line``); a map's lines are the rows of its grid, so they run over
its ``impact_obliquity`` and the grid over (``impact_obliquity``, ``impact_speed``).
The sphere and the plate are one value each, over ``sphere`` and ``plate`` (size 1:
HDF5 checksums chunked data only, and a scalar has no chunks).
"""

from __future__ import annotations

import math

import numpy as np

from ..base.errors import ParameterError
from ..model.tables import column_declaration, long_name
from ..storage.records import Record, RecordColumn, index_column, stored
from .lines import NAMED_LIMITS, OBLIQUITY, SPEED
from .maps import OutcomeMap
from .plate_limits import Limits
from .regimes import REGIME_FLAGS

#: The dimensions of a record: its lines (limits; a map's lines are its rows), its
#: boundaries, its sphere and its plate.
LINE, BOUNDARY, SPHERE, PLATE = "line", "boundary", "sphere", "plate"
#: Each axis's SI unit and name, and the other axis (a line's fixed coordinate).
UNITS = {SPEED: "m/s", OBLIQUITY: "rad"}
NAMES = {SPEED: "impact speed", OBLIQUITY: "impact obliquity"}
OTHER = {SPEED: OBLIQUITY, OBLIQUITY: SPEED}
_CODES = "regime code 2 x outcome + plate_failed (flag_values, flag_meanings)"
#: Where records written before records were netCDF held each column of a line or a
#: boundary (a named limit ``lines/NAME``).
LEGACY = {
    "line_start": "lines/start", "line_end": "lines/end", "first_regime": "lines/first",
    "boundary_line": "boundaries/line", "boundary_low": "boundaries/low",
    "boundary_high": "boundaries/high", "boundary_at": "boundaries/at",
    "regime_below": "boundaries/below", "regime_above": "boundaries/above",
}  # fmt: skip


def _line_columns(limits: Limits, dimension: str) -> dict[str, RecordColumn]:
    """The lines over ``dimension``: ``line`` (with the fixed coordinate of each) or a
    map's ``impact_obliquity`` (its rows, the fixed coordinate itself)."""
    axis, lines = limits.axis, limits.lines
    unit, other, along = UNITS[axis], OTHER[axis], NAMES[axis]
    label = other if dimension == LINE else ""

    def line_column(values: np.ndarray, units: str, name: str, description: str,
                    flags: bool = False) -> RecordColumn:  # fmt: skip
        flagged = REGIME_FLAGS if flags else None
        return RecordColumn(values, units, name, description, (dimension,), flagged, label)

    columns = {}
    if dimension == LINE:
        columns[LINE] = index_column(LINE, len(lines), "line")
        columns[other] = RecordColumn(
            np.array([line.fixed for line in lines]), UNITS[other], NAMES[other],
            f"the {NAMES[other]} at which each line runs along {along}", (LINE,),
        )  # fmt: skip
    columns |= {
        "line_start": line_column(
            np.array([line.start for line in lines]), unit, f"start {along}",
            "where each line starts",
        ),
        "line_end": line_column(
            np.array([line.end for line in lines]), unit, f"end {along}", "where each line ends"
        ),
        "first_regime": line_column(
            np.array([line.first.code for line in lines], dtype=np.int8), "1", "first regime",
            f"each line's regime at its start: {_CODES}", flags=True,
        ),
    }  # fmt: skip
    for declared in NAMED_LIMITS[axis]:
        values = [getattr(line, declared.name) for line in lines]
        columns[declared.name] = line_column(
            np.array([math.nan if v is None else v for v in values]), declared.unit or "1",
            long_name(declared), f"the {declared.description} (NaN: none on the line)",
        )  # fmt: skip
    return columns


def _boundary_columns(limits: Limits, lines: str) -> dict[str, RecordColumn]:
    """Every boundary, sorted by line then position, over ``boundary``."""
    unit, along = UNITS[limits.axis], NAMES[limits.axis]
    found = [(i, b) for i, line in enumerate(limits.lines) for b in line.boundaries]
    dims = (BOUNDARY,)

    def codes(values: list[int], name: str) -> RecordColumn:
        return RecordColumn(np.array(values, dtype=np.int8), "1", name, _CODES, dims,
                            REGIME_FLAGS)  # fmt: skip

    return {
        BOUNDARY: index_column(BOUNDARY, len(found), "boundary"),
        "boundary_line": RecordColumn(
            np.array([i for i, _ in found], dtype=np.int32), "1", "line",
            f"index of the boundary's line along {lines}", dims,
        ),
        "boundary_low": RecordColumn(
            np.array([b.low for _, b in found], dtype=float), unit, f"{along} below",
            "a scene here ends in the regime below", dims,
        ),
        "boundary_high": RecordColumn(
            np.array([b.high for _, b in found], dtype=float), unit, f"{along} above",
            "a scene here ends in the regime above", dims,
        ),
        "boundary_at": RecordColumn(
            np.array([b.at for _, b in found], dtype=float), unit, f"boundary {along}",
            "midpoint of low and high, within half the tolerance", dims,
        ),
        "regime_below": codes([b.below.code for _, b in found], "regime below"),
        "regime_above": codes([b.above.code for _, b in found], "regime above"),
    }  # fmt: skip


def _body_columns(limits: Limits) -> dict[str, RecordColumn]:
    """The sphere's radius and mass, the plate's thickness and constants (as their
    plug-ins declare them)."""
    assert limits.registry is not None  # plate_record refused it otherwise
    declared = limits.registry.plate_constants
    columns = {SPHERE: index_column(SPHERE, 1, "sphere"), PLATE: index_column(PLATE, 1, "plate")}
    for body, name, value in [
        (SPHERE, "radius", limits.sphere.radius),
        (SPHERE, "mass", limits.sphere.mass),
        (PLATE, "thickness", limits.plate.thickness),
        *((PLATE, name, value) for name, value in limits.plate.constants),
    ]:
        parameter = column_declaration(name, declared)
        columns[f"{body}_{name}"] = RecordColumn(
            np.array([value]), parameter.unit or "1", f"{body} {long_name(parameter)}",
            parameter.description, (body,),
        )  # fmt: skip
    return columns


def _map_columns(found: OutcomeMap) -> dict[str, RecordColumn]:
    grid = (OBLIQUITY, SPEED)
    fixed = np.array([line.fixed for line in found.limits.lines])
    if not np.array_equal(fixed, found.obliquities) or found.limits.axis != SPEED:
        raise ParameterError(
            "found", "an outcome map's limits must be along impact speed at its rows' obliquities"
        )
    return {
        SPEED: RecordColumn(
            found.speeds, "m/s", "impact speed", "the grid's columns", (SPEED,)
        ),
        OBLIQUITY: RecordColumn(
            found.obliquities, "rad", "impact obliquity",
            "the grid's rows, and the obliquity of each line", (OBLIQUITY,),
        ),
        "regime": RecordColumn(
            found.regime, "1", "regime", f"each cell's regime: {_CODES}", grid, REGIME_FLAGS
        ),
        "exit_speed": RecordColumn(
            found.exit_speed, "m/s", "exit speed", "each cell's exit speed (0 at rest)", grid
        ),
        "exit_obliquity": RecordColumn(
            found.exit_obliquity, "rad", "exit obliquity", "each cell's exit obliquity", grid
        ),
    }  # fmt: skip


def record_columns(found: Limits | OutcomeMap) -> dict[str, RecordColumn]:
    """The columns of the record of ``found`` (SI)."""
    limits = found.limits if isinstance(found, OutcomeMap) else found
    lines = OBLIQUITY if isinstance(found, OutcomeMap) else LINE
    columns = _body_columns(limits) | _line_columns(limits, lines)
    columns |= _boundary_columns(limits, lines)
    if isinstance(found, OutcomeMap):
        columns |= _map_columns(found)
    return columns


def line_data(record: Record, name: str) -> np.ndarray:
    """The line or boundary column ``name`` of ``record`` (a named limit by its name)."""
    return stored(record, name, LEGACY.get(name, f"lines/{name}"))


def body_data(record: Record) -> tuple[float, float, float, dict[str, float]]:
    """The sphere's radius and mass, the plate's thickness and constants, of ``record``."""

    def one(where: str) -> float:
        return float(stored(record, where.replace("/", "_"), where)[0])

    prefix = "plate_" if "plate_thickness" in record.columns else "plate/"
    constants = {
        where.removeprefix(prefix): float(column.data[0])
        for where, column in record.columns.items()
        if where.startswith(prefix) and where != f"{prefix}thickness"
    }
    return one("sphere/radius"), one("sphere/mass"), one("plate/thickness"), constants
