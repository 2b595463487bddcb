"""Limits and outcome maps in study archives (docs/archive.md, "Limits and outcome maps").

A :class:`Limits` or an :class:`OutcomeMap` becomes a storage record (plain attributes
and datasets with units, storage.records) and back: everything needed to rebuild it
bit for bit, and to review it in plain h5py (SI values, every dataset with ``units``,
``long_name`` and ``description``; the regime codes spelt out in an attribute).
"""

from __future__ import annotations

import datetime as dt
import json
import math
import os
import socket
from typing import Any

import numpy as np

from ..base.errors import ArchiveError, ParameterError, PlateImpactError
from ..base.parameters import Parameter
from ..base.untrusted import printable
from ..model.bodies import MASS, RADIUS, THICKNESS, Plate, Sphere
from ..model.tables import long_name
from ..provenance.metadata import git_commit, versions
from ..registry.plugin_registry import PluginRegistry
from ..storage import stored_attributes as typed
from ..storage.archive import Archive
from ..storage.plate_file import FORMAT as PLATE_FORMAT
from ..storage.records import Record, RecordColumn
from .lines import NAMED_LIMITS, OBLIQUITY, SPEED, Boundary, LimitLine
from .maps import OutcomeMap
from .plate_limits import Limits
from .regimes import REGIMES, Regime

KIND_LIMITS, KIND_MAP = "limits", "outcome_map"
#: A record's attributes by type: JSON objects, texts and numbers (docs/archive.md).
JSON_ATTRIBUTES = ("plate", "model", "versions", "regimes")
TEXT_ATTRIBUTES = ("kind", "axis", "axis_units", "tolerance_units", "resolution_units",
                   "git_commit", "host", "creation_time", "description")  # fmt: skip
NUMBER_ATTRIBUTES = ("tolerance", "resolution", "scenes", "passes", "wall_time_s")
#: Each axis's SI unit and name.
UNITS = {SPEED: "m/s", OBLIQUITY: "rad"}
NAMES = {SPEED: "impact speed", OBLIQUITY: "impact obliquity"}
_OTHER = {SPEED: OBLIQUITY, OBLIQUITY: SPEED}
_CODES = "regime code 2 x outcome + plate_failed (see the regimes attribute)"


def _axis_columns(limits: Limits) -> dict[str, RecordColumn]:
    axis, lines = limits.axis, limits.lines
    unit, other = UNITS[axis], _OTHER[axis]
    along = NAMES[axis]

    def named(value: float | None) -> float:
        return math.nan if value is None else value

    columns = {
        "lines/fixed": RecordColumn(
            np.array([line.fixed for line in lines]),
            UNITS[other],
            NAMES[other],
            f"the {NAMES[other]} at which each line runs along {along}",
        ),
        "lines/start": RecordColumn(
            np.array([line.start for line in lines]),
            unit,
            f"start {along}",
            "where each line starts",
        ),
        "lines/end": RecordColumn(
            np.array([line.end for line in lines]), unit, f"end {along}", "where each line ends"
        ),
        "lines/first": RecordColumn(
            np.array([line.first.code for line in lines], dtype=np.int8),
            "1",
            "first regime",
            f"each line's regime at its start: {_CODES}",
        ),
    }
    for declared in NAMED_LIMITS[axis]:
        values = [named(getattr(line, declared.name)) for line in lines]
        columns[f"lines/{declared.name}"] = RecordColumn(
            np.array(values),
            declared.unit,
            long_name(declared),
            f"the {declared.description} (NaN: none on the line)",
        )
    found = [(i, b) for i, line in enumerate(lines) for b in line.boundaries]
    at = np.array([b.at for _, b in found], dtype=float)
    columns |= {
        "boundaries/line": RecordColumn(
            np.array([i for i, _ in found], dtype=np.int32),
            "1",
            "line",
            "index of the boundary's line in lines/",
        ),
        "boundaries/low": RecordColumn(
            np.array([b.low for _, b in found], dtype=float),
            unit,
            f"{along} below",
            "a scene here ends in the regime below",
        ),
        "boundaries/high": RecordColumn(
            np.array([b.high for _, b in found], dtype=float),
            unit,
            f"{along} above",
            "a scene here ends in the regime above",
        ),
        "boundaries/at": RecordColumn(
            at, unit, f"boundary {along}", "midpoint of low and high, within half the tolerance"
        ),
        "boundaries/below": RecordColumn(
            np.array([b.below.code for _, b in found], dtype=np.int8), "1", "regime below", _CODES
        ),
        "boundaries/above": RecordColumn(
            np.array([b.above.code for _, b in found], dtype=np.int8), "1", "regime above", _CODES
        ),
    }
    return columns


def _body_columns(
    sphere: Sphere, plate: Plate, registry: PluginRegistry
) -> dict[str, RecordColumn]:
    declared = registry.plate_constants
    columns = {}
    for where, parameter, value in [
        ("sphere/radius", RADIUS, sphere.radius),
        ("sphere/mass", MASS, sphere.mass),
        ("plate/thickness", THICKNESS, plate.thickness),
        *((f"plate/{name}", declared.get(name), value) for name, value in plate.constants),
    ]:
        parameter = parameter or Parameter(where, "plate constant (no plug-in declares it)")
        columns[where] = RecordColumn(
            np.array([value]), parameter.unit or "1", parameter.name, parameter.description
        )
    return columns


def to_record(found: Limits | OutcomeMap) -> Record:
    """The record of ``found`` (plain attributes and datasets, SI)."""
    limits = found.limits if isinstance(found, OutcomeMap) else found
    unit = UNITS[limits.axis]
    kind = KIND_MAP if isinstance(found, OutcomeMap) else KIND_LIMITS
    what = "outcome map" if kind == KIND_MAP else f"limits along {NAMES[limits.axis]}"
    plate = {"format": PLATE_FORMAT, **limits.plate_record()}
    attributes: dict[str, object] = {
        "kind": kind,
        "description": f"{what} of {plate['material']} {plate[THICKNESS.key]:g} mm; "
        "see docs/archive.md",
        "axis": limits.axis,
        "axis_units": unit,
        "tolerance": limits.tolerance,
        "tolerance_units": unit,
        "resolution": limits.resolution,
        "resolution_units": unit,
        "plate": json.dumps(plate),
        "model": json.dumps(limits.model, sort_keys=True),
        "versions": json.dumps(versions(), sort_keys=True),
        "git_commit": git_commit(),
        "host": socket.gethostname(),
        "creation_time": dt.datetime.now(dt.UTC).isoformat(),
        "scenes": int(limits.scenes),
        "passes": int(limits.passes),
        "wall_time_s": float(limits.seconds),
        "regimes": json.dumps({str(r.code): r.label for r in REGIMES}),
    }
    if limits.plugins is not None:  # the code that found them (docs/archive.md, Provenance)
        attributes["plugins"] = json.dumps(limits.plugins, sort_keys=True)
    assert limits.registry is not None  # plate_record refused it otherwise
    columns = _body_columns(limits.sphere, limits.plate, limits.registry) | _axis_columns(limits)
    if isinstance(found, OutcomeMap):
        columns |= {
            "map/speeds": RecordColumn(found.speeds, "m/s", "impact speed", "the grid's columns"),
            "map/obliquities": RecordColumn(
                found.obliquities, "rad", "impact obliquity", "the grid's rows"
            ),
            "map/regime": RecordColumn(
                found.regime, "1", "regime", f"rows: obliquities, columns: speeds; {_CODES}"
            ),
            "map/exit_speed": RecordColumn(
                found.exit_speed,
                "m/s",
                "exit speed",
                "rows: obliquities, columns: speeds (0 at rest)",
            ),
            "map/exit_obliquity": RecordColumn(
                found.exit_obliquity, "rad", "exit obliquity", "rows: obliquities, columns: speeds"
            ),
        }
    return Record(attributes, columns)


def _plugins(attributes: dict[str, object], what: str) -> dict[str, Any] | None:
    """The recorded ``plugins`` (None in records made before they were recorded)."""
    if "plugins" not in attributes:
        return None
    found: dict[str, Any] = typed.json_value(attributes, "plugins", what, dict)
    return found


def _number(attributes: dict[str, object], key: str) -> float:
    value = attributes[key]
    if isinstance(value, bool) or not isinstance(value, int | float):
        raise TypeError(f"attribute {key} is {value!r:.40}, not a number")
    return float(value)


def from_record(
    record: Record, what: str = "stored limits", registry: PluginRegistry | None = None
) -> Limits | OutcomeMap:
    """The limits or map a record holds (ValueError, KeyError or TypeError if it is
    not one; ArchiveError naming ``what`` for an attribute of the wrong type: they come
    from a file, maybe someone else's); ``registry`` describes their plate when they
    are written again (Limits.plate_record)."""
    attributes, columns = record.attributes, record.columns

    def data(where: str) -> np.ndarray:
        return columns[where].data

    kind, axis = typed.text(attributes, "kind", what), typed.text(attributes, "axis", what)
    if kind not in (KIND_LIMITS, KIND_MAP) or axis not in UNITS:
        raise ValueError(f"kind {kind!r} along {axis!r} is not one this plateimpact reads")
    sphere = Sphere(float(data("sphere/radius")[0]), float(data("sphere/mass")[0]))
    constants = {
        where.split("/", 1)[1]: float(column.data[0])
        for where, column in columns.items()
        if where.startswith("plate/") and where != "plate/thickness"
    }
    material = typed.json_value(attributes, "plate", what, dict).get("material")
    if not isinstance(material, str):
        raise ArchiveError(f"{what}: attribute plate names no material")
    plate = Plate(material, float(data("plate/thickness")[0]), constants)
    index, low, high = data("boundaries/line"), data("boundaries/low"), data("boundaries/high")
    below, above = data("boundaries/below"), data("boundaries/above")
    lines = []
    for i, (fixed, start, end, first) in enumerate(
        zip(data("lines/fixed"), data("lines/start"), data("lines/end"), data("lines/first"),
            strict=True)
    ):  # fmt: skip
        mine = np.flatnonzero(index == i)
        boundaries = tuple(
            Boundary(float(low[k]), float(high[k]), Regime.of_code(below[k]),
                     Regime.of_code(above[k]))
            for k in mine
        )  # fmt: skip
        lines.append(LimitLine(axis, float(fixed), float(start), float(end), boundaries,
                               Regime.of_code(first)))  # fmt: skip
    limits = Limits(
        axis,
        tuple(lines),
        _number(attributes, "tolerance"),
        _number(attributes, "resolution"),
        sphere,
        plate,
        typed.json_value(attributes, "model", what, dict),
        int(_number(attributes, "scenes")),
        int(_number(attributes, "passes")),
        _number(attributes, "wall_time_s"),
        _plugins(attributes, what),
        registry=registry,
    )
    if kind == KIND_LIMITS:
        return limits
    return OutcomeMap(
        data("map/speeds"),
        data("map/obliquities"),
        data("map/regime"),
        data("map/exit_speed"),
        data("map/exit_obliquity"),
        limits,
    )


def _archive(archive: Archive | str | os.PathLike[str]) -> Archive:
    if isinstance(archive, Archive):
        return archive
    if isinstance(archive, str | os.PathLike):
        return Archive(archive)
    raise ParameterError("archive", f"archive must be an Archive or a path, got {archive!r:.80}")


def archive_limits(
    archive: Archive | str | os.PathLike[str],
    name: str,
    found: Limits | OutcomeMap,
    *,
    overwrite: bool = False,
) -> str:
    """Store ``found`` (limits or an outcome map) in ``archive`` as ``/limits/NAME``
    (``NAME.2``, ``NAME.3``, ... if the name is taken; with ``overwrite``, in its
    place), atomically and under the archive's lock as runs are added; returns the name
    it was stored under."""
    if not isinstance(found, Limits | OutcomeMap):
        raise ParameterError(
            "found", f"found must be Limits or an OutcomeMap, got {type(found).__name__}"
        )
    return _archive(archive).append_record(name, to_record(found), overwrite=overwrite)


def read_limits(
    archive: Archive | str | os.PathLike[str], name: str, registry: PluginRegistry | None = None
) -> Limits | OutcomeMap:
    """The limits or map stored as ``name`` (``NAME`` or ``limits/NAME``), as written;
    ArchiveError if the archive or the record is damaged, UnknownNameError if there is
    no such name (the message lists those there are). With ``registry`` (its plate
    constants' declarations) they can be printed as JSON or stored again."""
    where = _archive(archive)
    record = where.record(name)
    what = f"archive {where.path}: limits {printable(name)}"
    kind = record.attributes.get("kind")
    if isinstance(kind, str) and kind not in (KIND_LIMITS, KIND_MAP):  # another kind of record
        raise ArchiveError(
            f"{what} holds {printable(kind, 40)}, not limits or an outcome map "
            "(plateimpact show describes it)"
        )
    try:
        return from_record(record, what, registry)
    except ArchiveError:
        raise
    except (KeyError, ValueError, TypeError, IndexError, AttributeError, PlateImpactError) as exc:
        reason = printable(str(exc).splitlines()[0] if str(exc) else "missing", 160)
        raise ArchiveError(
            f"{what} cannot be read back ({type(exc).__name__}: {reason}); the record is damaged"
        ) from None


def stored_limits(archive: Archive | str | os.PathLike[str]) -> list[str]:
    """The names of the limits and maps stored in ``archive``, in the order written."""
    return _archive(archive).limits_names()


def attributes_of(archive: Archive | str | os.PathLike[str], name: str) -> dict[str, Any]:
    """The stored attributes of ``name`` (checked), JSON ones decoded and every one the
    listings use typed (ArchiveError, one line, if one is not what the format says)."""
    where = _archive(archive)
    attributes = where.record(name).attributes
    what = f"archive {where.path}: limits {printable(name)}"
    out: dict[str, Any] = dict(attributes)
    for key in JSON_ATTRIBUTES:
        out[key] = typed.json_value(attributes, key, what, dict)
    if "plugins" in attributes:  # optional: records made before it was recorded lack it
        out["plugins"] = typed.json_value(attributes, "plugins", what, dict)
    for key in TEXT_ATTRIBUTES:
        out[key] = typed.text(attributes, key, what)
    for key in NUMBER_ATTRIBUTES:
        out[key] = typed.number(attributes, key, what)
    return out
