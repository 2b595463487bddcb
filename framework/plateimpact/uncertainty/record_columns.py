"""The columns of an uncertainty study's stored records (docs/uncertainty.md, "Archives
and resume"): netCDF variables over named dimensions, SI, each with CF ``units`` and
``long_name``, built from plain arrays, so that a record read back (in either layout)
is written again the same way (``plateimpact export --record``).

The grids keep the order they were asked in (any order, repeats allowed), so their
dimensions are indices (``obliquity``, ``speed``, ``sample``, ``input``) with the values
as auxiliary coordinates (``impact_obliquity``, ``impact_speed``, ``input_name``);
the searched speed range runs over ``bound`` (0: start, 1: end).
"""

from __future__ import annotations

from collections.abc import Mapping, Sequence

import numpy as np

from ..model.tables import column_declaration, long_name
from ..registry.plugin_registry import PluginRegistry
from ..storage.records import Record, RecordColumn, index_column, stored

OBLIQUITY, SPEED, SAMPLE, BOUND, INPUT = "obliquity", "speed", "sample", "bound", "input"
#: A sampled input's column: ``sampled_<scene column>`` (before netCDF: ``samples/...``).
SAMPLED, LEGACY_SAMPLED = "sampled_", "samples/"
#: Each index quantity's columns, with their long names.
INDEX_KEYS = {"first": "first-order index", "first_halfwidth": "first-order index's half-width",
              "total": "total index", "total_halfwidth": "total index's half-width"}  # fmt: skip


#: The columns of sampled limits whose names netCDF kept: per obliquity and sample, per
#: obliquity, and the range searched.
LIMITS_KEPT = ("ballistic_limit", "ricochet_limit", "perforation_gaps", "ricochet_gaps",
               "speed_range")  # fmt: skip


def limits_columns(
    obliquities: np.ndarray, found: Mapping[str, np.ndarray], samples: Mapping[str, np.ndarray],
    registry: PluginRegistry, sampling: str,
) -> dict[str, RecordColumn]:  # fmt: skip
    """The sampled limits [m/s] at each obliquity [rad] (rows) and sample (columns),
    each obliquity's gaps and the speed range searched (``found``, by the names of
    :data:`LIMITS_KEPT`), and the samples [SI] by scene column (``sampling``: how they
    were drawn)."""
    rows, grid = (OBLIQUITY,), (OBLIQUITY, SAMPLE)
    columns = {
        OBLIQUITY: index_column(OBLIQUITY, len(obliquities), "obliquity"),
        SAMPLE: index_column(SAMPLE, np.shape(found["ballistic_limit"])[1], "sample"),
        BOUND: RecordColumn(np.arange(2, dtype=np.int8), "1", "bound",
                            "which end of the speed range", (BOUND,), ([0, 1], "start end")),
        "impact_obliquity": RecordColumn(obliquities, "rad", "impact obliquity",
                                         "the obliquity of each row", rows),
        "speed_range": RecordColumn(found["speed_range"], "m/s", "impact speed",
                                    "the range searched (start, end)", (BOUND,)),
    }  # fmt: skip
    for name, outside in (
        ("ballistic_limit", "-inf: perforates at every speed of the range, +inf: at none"),
        ("ricochet_limit", "-inf: ricochets at no speed of the range, +inf: at every one"),
    ):
        columns[name] = RecordColumn(
            found[name], "m/s", name.replace("_", " "),
            f"each sample's at each obliquity; {outside}", grid, coordinates="impact_obliquity",
        )  # fmt: skip
    for name, band in (("perforation_gaps", "a perforation band below a non-perforating one"),
                       ("ricochet_gaps", "a ricochet band above a non-ricochet one")):  # fmt: skip
        columns[name] = RecordColumn(
            found[name], "1", name.replace("_", " "), f"samples with {band}, per obliquity",
            rows, coordinates="impact_obliquity",
        )  # fmt: skip
    for column, values in samples.items():
        declared = column_declaration(column, registry.plate_constants)
        columns[f"{SAMPLED}{column}"] = RecordColumn(
            values, declared.unit or "1", f"sampled {long_name(declared)}",
            f"{declared.description}: each sample's ({sampling})", (SAMPLE,),
        )  # fmt: skip
    return columns


def indices_columns(
    names: Sequence[str], found: Mapping[str, Mapping[str, np.ndarray]]
) -> dict[str, RecordColumn]:
    """Each quantity's indices and their half-widths (dimensionless), one per input
    (``names``, the same inputs for every quantity), as ``QUANTITY_first``, ...."""
    columns = {
        INPUT: index_column(INPUT, len(names), "input"),
        "input_name": RecordColumn(np.array(list(names), dtype=object), "", "input name",
                                   "the spec's name of each input", (INPUT,)),
    }  # fmt: skip
    for quantity, indices in found.items():
        for key, name in INDEX_KEYS.items():
            columns[f"{quantity}_{key}"] = RecordColumn(
                indices[key], "1", name, f"of {quantity}, one per input"
                + (f" (its bootstrap interval at {quantity}_confidence)" if "half" in key else ""),
                (INPUT,), coordinates="input_name",
            )  # fmt: skip
    return columns


def map_columns(
    speeds: np.ndarray, obliquities: np.ndarray, counts: Mapping[str, np.ndarray]
) -> dict[str, RecordColumn]:
    """How many samples end in each outcome at each point of the grid of ``speeds``
    [m/s] (rows) and ``obliquities`` [rad] (columns)."""
    grid = (SPEED, OBLIQUITY)
    return {
        SPEED: index_column(SPEED, len(speeds), "speed"),
        OBLIQUITY: index_column(OBLIQUITY, len(obliquities), "obliquity"),
        "impact_speed": RecordColumn(speeds, "m/s", "impact speed", "the rows", (SPEED,)),
        "impact_obliquity": RecordColumn(
            obliquities, "rad", "impact obliquity", "the columns", (OBLIQUITY,)
        ),
        **{
            f"{outcome}_count": RecordColumn(
                count,
                "1",
                f"{outcome} count",
                f"samples ending in {outcome} at each point",
                grid,
                coordinates="impact_speed impact_obliquity",
            )  # fmt: skip
            for outcome, count in counts.items()
        },
    }


def limits_data(record: Record) -> dict[str, np.ndarray]:
    """The columns of :data:`LIMITS_KEPT` of a limits record (either layout)."""
    return {name: stored(record, name, name) for name in LIMITS_KEPT}


def samples_of(record: Record) -> dict[str, np.ndarray]:
    """The sampled inputs a limits record holds [SI], by scene column."""
    return {
        where.removeprefix(prefix): column.data
        for where, column in record.columns.items()
        for prefix in (SAMPLED, LEGACY_SAMPLED)
        if where.startswith(prefix)
    }


def index_data(record: Record, quantity: str, key: str) -> np.ndarray:
    """``quantity``'s ``key`` column (``first``, ``total`` or their ``_halfwidth``)."""
    return stored(record, f"{quantity}_{key}", f"{quantity}/{key}")


def count_data(record: Record, outcome: str) -> np.ndarray:
    return stored(record, f"{outcome}_count", f"counts/{outcome}")


def grid_data(record: Record, name: str) -> np.ndarray:
    """``impact_speed`` or ``impact_obliquity`` (before netCDF: ``speeds``,
    ``obliquities``)."""
    return stored(record, name, {"impact_speed": "speeds"}.get(name, "obliquities"))
