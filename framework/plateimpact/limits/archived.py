"""Limits and outcome maps in study archives (docs/archive.md, "Limits and outcome maps").

A :class:`Limits` or an :class:`OutcomeMap` becomes a storage record (plain attributes
and columns with units, storage.records; the columns: limits.record_columns) and back:
everything needed to rebuild it bit for bit, and to review it without plateimpact in
any netCDF tool (SI values, CF ``units``, ``long_name`` and flags on every variable;
the regime codes also spelt out in an attribute). Records written before records were
netCDF read back as well.
"""

from __future__ import annotations

import datetime as dt
import json
import os
import socket
from typing import Any

import numpy as np

from ..base.errors import ArchiveError, ParameterError
from ..base.untrusted import printable
from ..model.bodies import THICKNESS, Plate, Sphere
from ..provenance.metadata import git_commit, versions
from ..registry.plugin_registry import PluginRegistry
from ..storage import stored_attributes as typed
from ..storage.archive import Archive
from ..storage.plate_file import FORMAT as PLATE_FORMAT
from ..storage.records import Record, reading, stored
from .lines import OBLIQUITY, SPEED, Boundary, LimitLine
from .maps import OutcomeMap
from .plate_limits import Limits
from .record_columns import NAMES, OTHER, UNITS, body_data, line_data, record_columns
from .regimes import REGIMES, Regime

KIND_LIMITS, KIND_MAP = "limits", "outcome_map"
#: A record's attributes by type: JSON objects, texts and numbers (docs/archive.md).
JSON_ATTRIBUTES = ("plate", "model", "versions", "regimes")
TEXT_ATTRIBUTES = ("kind", "axis", "axis_units", "tolerance_units", "resolution_units",
                   "git_commit", "host", "creation_time", "description")  # fmt: skip
NUMBER_ATTRIBUTES = ("tolerance", "resolution", "scenes", "passes", "wall_time_s")


def _title(found: Limits | OutcomeMap) -> str:
    """What ``found`` is: ``limits along impact speed of 2024-T3 3.18 mm``."""
    limits = found.limits if isinstance(found, OutcomeMap) else found
    what = "outcome map" if isinstance(found, OutcomeMap) else f"limits along {NAMES[limits.axis]}"
    return f"{what} of {limits.plate.material} {limits.plate.thickness / THICKNESS.scale:g} mm"


def to_record(found: Limits | OutcomeMap) -> Record:
    """The record of ``found`` (plain attributes and columns, SI)."""
    limits = found.limits if isinstance(found, OutcomeMap) else found
    unit = UNITS[limits.axis]
    kind = KIND_MAP if isinstance(found, OutcomeMap) else KIND_LIMITS
    plate = {"format": PLATE_FORMAT, **limits.plate_record()}
    attributes: dict[str, object] = {
        "kind": kind,
        "description": f"{_title(found)}; see docs/archive.md",
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
    return Record(attributes, record_columns(found), _title(found))


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
    attributes = record.attributes
    kind, axis = typed.text(attributes, "kind", what), typed.text(attributes, "axis", what)
    if kind not in (KIND_LIMITS, KIND_MAP) or axis not in UNITS:
        raise ValueError(f"kind {kind!r} along {axis!r} is not one this plateimpact reads")
    radius, mass, thickness, constants = body_data(record)
    material = typed.json_value(attributes, "plate", what, dict).get("material")
    if not isinstance(material, str):
        raise ArchiveError(f"{what}: attribute plate names no material")
    plate = Plate(material, thickness, constants)
    index, low, high = (line_data(record, f"boundary_{k}") for k in ("line", "low", "high"))
    below, above = line_data(record, "regime_below"), line_data(record, "regime_above")
    fixed = stored(record, OTHER[axis], "lines/fixed")  # a map's: the rows of its grid
    starts = line_data(record, "line_start")
    if fixed.shape != starts.shape:
        raise ValueError(f"{fixed.size} fixed coordinates for {starts.size} lines")
    lines = []
    for i, (start, end, first) in enumerate(
        zip(starts, line_data(record, "line_end"), line_data(record, "first_regime"),
            strict=True)
    ):  # fmt: skip
        mine = np.flatnonzero(index == i)
        boundaries = tuple(
            Boundary(float(low[k]), float(high[k]), Regime.of_code(below[k]),
                     Regime.of_code(above[k]))
            for k in mine
        )  # fmt: skip
        lines.append(LimitLine(axis, float(fixed[i]), float(start), float(end), boundaries,
                               Regime.of_code(first)))  # fmt: skip
    limits = Limits(
        axis,
        tuple(lines),
        _number(attributes, "tolerance"),
        _number(attributes, "resolution"),
        Sphere(radius, mass),
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
        stored(record, SPEED, "map/speeds"),
        stored(record, OBLIQUITY, "map/obliquities"),
        stored(record, "regime", "map/regime"),
        stored(record, "exit_speed", "map/exit_speed"),
        stored(record, "exit_obliquity", "map/exit_obliquity"),
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
    return _read_back(record, what, registry)


def _read_back(record: Record, what: str, registry: PluginRegistry | None) -> Limits | OutcomeMap:
    """:func:`from_record`, every failure an ArchiveError naming ``what`` (one line)."""
    with reading(what):
        return from_record(record, what, registry)


def cf_record(record: Record, what: str, registry: PluginRegistry) -> Record:
    """The stored limits or map ``record`` (either layout), as this plateimpact writes
    it: its attributes as stored, its columns over their dimensions (for export)."""
    with reading(what):  # a map whose lines are not its rows, too
        found = from_record(record, what, registry)
        return Record(record.attributes, record_columns(found), _title(found))


#: Each kind's :func:`cf_record`, for ``plateimpact export --record``.
CF_RECORDS = {KIND_LIMITS: cf_record, KIND_MAP: cf_record}


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
