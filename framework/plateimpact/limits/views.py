"""How limits, outcome maps and their comparisons show in a notebook and in labelled
tables: a short text (``__repr__``), a small HTML table (``_repr_html_``), and the rows
of a limits' lines or a map's grid as an xarray Dataset or a pandas DataFrame
(:class:`~plateimpact.model.tables.LabelledTable`). Positions are shown in the user's
unit of their axis (m/s, deg), boundaries to the decimals the tolerance resolves.

The objects are read through their attributes, so that this module, below the classes
that use it, imports none of them.
"""

from __future__ import annotations

import json
import math
from typing import Any

import numpy as np

from ..base.display import (
    cell,
    heading,
    html_block,
    html_fields,
    html_table,
    number,
    preview,
    quantity,
    short_repr,
    spread,
)
from ..base.parameters import Parameter
from ..model.bodies import MASS, RADIUS, THICKNESS
from ..model.fields import CORE_COLUMNS, RESULT_FIELDS
from ..model.tables import Column, LabelledTable
from ..model.views import label
from ..registry.described import plugin_line
from ..registry.plugin_registry import KINDS, PluginRegistry
from .lines import NAMED_LIMITS, OBLIQUITY, SPEED, LimitLine
from .regimes import Regime

#: Each axis's declaration, and the other axis of a line along it.
AXES = {SPEED: CORE_COLUMNS[SPEED], OBLIQUITY: CORE_COLUMNS[OBLIQUITY]}
OTHER = {SPEED: OBLIQUITY, OBLIQUITY: SPEED}


def decimals(axis: str, tolerance: float) -> int:
    """Decimals that show a boundary on ``axis`` to the ``tolerance`` it was found to."""
    return max(0, -math.floor(math.log10(tolerance / AXES[axis].scale)))


def band_texts(
    axis: str, line: LimitLine, digits: int, outcomes: list[str] | None = None
) -> list[str]:
    """``ricochet 50.00-184.63`` for each band of ``line`` (of ``outcomes`` only, if
    given), in the axis's unit to ``digits`` decimals."""
    declared = AXES[axis]
    return [
        f"{b.regime.label} {number(declared, b.start, digits, 'f')}-"
        f"{number(declared, b.end, digits, 'f')}"
        for b in line.bands
        if not outcomes or b.regime.outcome.label in outcomes
    ]


def _named(line: LimitLine, declared: Parameter) -> float | None:
    value = getattr(line, declared.name)
    return None if value is None else float(value)


def _plate(found: Any) -> str:
    plate = found.plate
    return f"{plate.material}, {quantity(THICKNESS, plate.thickness)}"


def _body_fields(found: Any) -> list[tuple[str, object]]:
    """The sphere and plate, each constant in the unit its plug-in declares (as stored
    [SI] where the limits carry no registry)."""
    declared = {} if found.registry is None else found.registry.plate_constants
    fields: list[tuple[str, object]] = [
        ("plate", found.plate.material),
        (heading("thickness", THICKNESS), cell(THICKNESS, found.plate.thickness)),
    ]
    for name, value in found.plate.constants:
        if name in declared:
            fields.append((heading(label(name), declared[name]), cell(declared[name], value)))
        else:
            fields.append((f"{label(name)} [SI]", f"{value:.6g}"))
    fields += [
        (heading("sphere radius", RADIUS), cell(RADIUS, found.sphere.radius)),
        (heading("sphere mass", MASS), cell(MASS, found.sphere.mass)),
    ]
    return fields


def model_fields(model: object, registry: PluginRegistry | None) -> list[tuple[str, object]]:
    """Each slot's plug-in with its version and settings (user units where ``registry``
    declares them)."""
    if not isinstance(model, dict):
        return [("model", str(model))]
    return [(kind, plugin_line(kind, model, registry)) for kind in KINDS]


def limits_repr(found: Any) -> str:
    axis, lines = found.axis, found.lines
    other = AXES[OTHER[axis]]
    fixed = np.array([line.fixed for line in lines])
    parts = [_plate(found), f"{len(lines)} lines along {label(axis)}, {label(OTHER[axis])} "
             f"{spread(other, fixed)}"]  # fmt: skip
    digits = decimals(axis, found.tolerance)
    for declared in NAMED_LIMITS[axis][::2]:  # the ballistic and ricochet limits, or the one
        values = [v for line in lines if (v := _named(line, declared)) is not None]
        none = len(lines) - len(values)
        text = spread(declared, np.array(values), digits=digits, style="f") if values else "none"
        lacking = f" (none on {none} of the lines)" if values and none else ""
        parts.append(f"{label(declared.name)} {text}{lacking}")
    parts.append(f"boundaries to {quantity(AXES[axis], found.tolerance)}")
    model = found.model if isinstance(found.model, dict) else {}
    parts.append(" + ".join(str(model.get(kind)) for kind in KINDS))
    return short_repr(type(found).__name__, parts)


def lines_table(found: Any) -> str:
    """One row per line: its fixed coordinate, its named limits and its bands."""
    axis = found.axis
    other = AXES[OTHER[axis]]
    digits = decimals(axis, found.tolerance)
    named = NAMED_LIMITS[axis]
    header = [heading(label(OTHER[axis]), other), *(heading(label(d.name), d) for d in named),
              heading("bands", AXES[axis])]  # fmt: skip
    shown, omitted = preview(len(found.lines))
    rows = [
        [cell(other, line.fixed), *(cell(d, _named(line, d), digits, "f") for d in named),
         " | ".join(band_texts(axis, line, digits))]
        for line in (found.lines[i] for i in shown)
    ]  # fmt: skip
    return html_table(header, rows, caption="lines", omitted=omitted)


def limits_html(found: Any) -> str:
    axis = AXES[found.axis]
    fields = [
        *_body_fields(found),
        *model_fields(found.model, found.registry),
        (heading("tolerance", axis), cell(axis, found.tolerance)),
        (heading("resolution", axis), cell(axis, found.resolution)),
        ("scenes run", f"{found.scenes:,}"),
    ]
    title = f"Limits along {label(found.axis)}: {_plate(found)}"
    return html_block(title, html_fields(fields, caption="what found them"), lines_table(found))


def limits_table(found: Any) -> LabelledTable:
    """The named limits of each line over the fixed coordinate [SI] (NaN: none), with the
    plate, sphere, model and tolerance as attributes."""
    axis, other = found.axis, OTHER[found.axis]
    coordinates: dict[str, Column] = {
        other: ((other,), np.array([line.fixed for line in found.lines]), AXES[other])
    }
    variables: dict[str, Column] = {}
    for declared in NAMED_LIMITS[axis]:
        values = [_named(line, declared) for line in found.lines]
        array = np.array([math.nan if v is None else v for v in values], dtype=float)
        variables[declared.name] = ((other,), array, declared)
    return LabelledTable((other,), coordinates, variables, _attributes(found))


def _attributes(found: Any) -> dict[str, object]:
    """What produced limits, as a Dataset's attributes [SI]."""
    plate, sphere = found.plate, found.sphere
    return {
        "axis": found.axis,
        "tolerance": found.tolerance,
        "resolution": found.resolution,
        "tolerance_units": AXES[found.axis].unit,
        "material": plate.material,
        "thickness": plate.thickness,
        "plate_constants": json.dumps(dict(plate.constants)),
        "sphere_radius": sphere.radius,
        "sphere_mass": sphere.mass,
        "model": json.dumps(found.model, default=str),
        "scenes": found.scenes,
    }


def map_table(found: Any) -> LabelledTable:
    """The map's grid over (impact_obliquity, impact_speed) [SI]: each cell's outcome,
    whether the plate failed, its exit speed and obliquity."""
    dims = (OBLIQUITY, SPEED)
    regime = np.asarray(found.regime, dtype=np.int64)
    coordinates: dict[str, Column] = {
        OBLIQUITY: ((OBLIQUITY,), np.asarray(found.obliquities), AXES[OBLIQUITY]),
        SPEED: ((SPEED,), np.asarray(found.speeds), AXES[SPEED]),
    }
    variables: dict[str, Column] = {  # a regime code is 2 x outcome + plate_failed
        "outcome": (dims, regime // 2, RESULT_FIELDS["outcome"]),
        "plate_failed": (dims, regime % 2 == 1, RESULT_FIELDS["plate_failed"]),
        "exit_speed": (dims, np.asarray(found.exit_speed), RESULT_FIELDS["exit_speed"]),
        "exit_obliquity": (dims, np.asarray(found.exit_obliquity), RESULT_FIELDS["exit_obliquity"]),
    }
    return LabelledTable(dims, coordinates, variables, _attributes(found.limits))


def map_repr(found: Any) -> str:
    rows, columns = found.shape
    grid = (f"{rows} obliquities x {columns} speeds: {spread(AXES[OBLIQUITY], found.obliquities)}, "
            f"{spread(AXES[SPEED], found.speeds)}")  # fmt: skip
    cells = "cells: " + ", ".join(f"{regime} {n:,}" for regime, n in _regime_cells(found))
    return short_repr("OutcomeMap", [_plate(found.limits), grid, cells])


def _regime_cells(found: Any) -> list[tuple[str, int]]:
    """(regime, cells) for each regime the map has."""
    codes, counts = np.unique(np.asarray(found.regime), return_counts=True)
    pairs = zip(codes, counts, strict=True)
    return [(Regime.of_code(int(c)).label, int(n)) for c, n in pairs]


def map_html(found: Any) -> str:
    rows, columns = found.shape
    grid: list[tuple[str, object]] = [
        (heading(label(axis), AXES[axis]), spread(AXES[axis], values, with_unit=False))
        for axis, values in ((OBLIQUITY, found.obliquities), (SPEED, found.speeds))
    ]
    cells = [[regime, f"{n:,}"] for regime, n in _regime_cells(found)]
    limits = found.limits
    title = f"OutcomeMap: {rows} obliquities x {columns} speeds, {_plate(limits)}"
    tables = [html_fields(grid, caption="grid"), html_table(["regime", "cells"], cells)]
    return html_block(title, *tables, lines_table(limits))


def comparison_parts(found: Any) -> tuple[list[str], list[list[object]]]:
    """The header and rows of every boundary of lines both have: where, which, A, B and
    B - A in the axis's unit."""
    axis, other = AXES[found.axis], AXES[found.fixed_axis]
    header = [heading(label(found.fixed_axis), other), "boundary", heading("A", axis),
              heading("B", axis), heading("B - A", axis)]  # fmt: skip
    rows: list[list[object]] = []
    for line in found.lines:
        for s in line.boundaries:
            a, b = (None if x is None else x.at for x in (s.a, s.b))
            which = f"{s.below.label} -> {s.above.label}"
            rows.append([cell(other, line.fixed), which, cell(axis, a), cell(axis, b),
                         cell(axis, s.shift)])  # fmt: skip
    return header, rows


def comparison_repr(found: Any) -> str:
    axis = AXES[found.axis]
    shifts = [s.shift for line in found.lines for s in line.boundaries if s.shift is not None]
    largest = max(shifts, key=abs) if shifts else None
    only = sum(len(x.bands_only_in_a) + len(x.bands_only_in_b) for x in found.lines)
    parts = [
        f"along {label(found.axis)}, {len(found.lines)} lines in both",
        f"{len(shifts)} boundaries in both"
        + ("" if largest is None else f", the largest shift {quantity(axis, largest)}"),
        f"{only} bands in one only",
        f"lines in A only {len(found.lines_only_in_a)}, in B only {len(found.lines_only_in_b)}",
    ]
    return short_repr("LimitsComparison", parts)


def comparison_html(found: Any) -> str:
    header, rows = comparison_parts(found)
    shown, omitted = preview(len(rows))
    title = f"LimitsComparison along {label(found.axis)}: B against A"
    table = html_table(header, [rows[i] for i in shown], caption="boundaries", omitted=omitted)
    return html_block(title, table)
