"""An uncertainty study's results in its archive, beside the propagation's study
(docs/uncertainty.md, "Archives and resume"): the sampled limits, the Sobol' indices and
the probability maps, each a stored record (storage.records: ``/limits/NAME``, its own
data file, appended atomically under the archive's lock) with SI datasets carrying their
units, and attributes holding the spec, the plate, the model and the code that made it.

A record's name is its kind and a digest of the spec and of the settings it depends on,
so that the same request finds its record again: ``resume`` reads it back instead of
computing it (when its recorded code is the code that would run now), and without
``resume`` a record that is already there is refused, never replaced or duplicated."""

from __future__ import annotations

import datetime as dt
import json
import math
import socket
from collections.abc import Callable, Mapping, Sequence
from typing import Any, TypeVar

import numpy as np

from ..base.errors import ArchiveError
from ..base.untrusted import printable
from ..provenance.code import limits_record, plugins_record
from ..provenance.metadata import git_commit, versions
from ..registry.plugin_registry import PluginRegistry
from ..run.simulation import Simulation
from ..storage import stored_attributes as typed
from ..storage.archive import Archive
from ..storage.plate_file import plate_to_dict
from ..storage.records import LIMITS, Record, RecordColumn, reading
from ..study.reruns import StaleRunError, check_code
from .curves import OutcomeGrid
from .inputs import input_table
from .limits import SampledLimits
from .propagation import OUTCOMES, sample_inputs, spec_digest
from .record_columns import (
    INDEX_KEYS,
    count_data,
    grid_data,
    index_data,
    indices_columns,
    limits_columns,
    limits_data,
    map_columns,
    samples_of,
)
from .sensitivity import SobolIndices
from .spec import UncertaintySpec

KIND_LIMITS, KIND_INDICES, KIND_MAP = "uncertainty_limits", "uncertainty_indices", "uncertainty_map"
#: Each kind's short name in a record's name, and what it is in messages.
SHORT = {KIND_LIMITS: "limits", KIND_INDICES: "indices", KIND_MAP: "map"}
WHAT = {KIND_LIMITS: "sampled limits", KIND_INDICES: "Sobol' indices",
        KIND_MAP: "probability map"}  # fmt: skip
Found = TypeVar("Found")


class RecordExistsError(ArchiveError):
    """The archive already holds this result of this spec: read it back (resume) or
    store into another archive; never replaced or stored twice."""


def record_name(spec: UncertaintySpec, kind: str, settings: Mapping[str, Any]) -> str:
    """``uncertainty-KIND-DIGEST``: the same spec and settings, the same name."""
    return f"uncertainty-{SHORT[kind]}-{spec_digest(spec, kind=kind, settings=settings)[:12]}"


def code_record(simulation: Simulation, searched: bool) -> dict[str, Any]:
    """The code a result depends on: the model's plug-ins and the core, and the limits
    finder's hash when it ``searched``."""
    return {**plugins_record(simulation), **({"limits": limits_record()} if searched else {})}


def _title(kind: str, plate: Mapping[str, Any]) -> str:
    """What a record is: ``Sobol' indices of an uncertainty study of 2024-T3 3.18 mm``."""
    return (
        f"{WHAT[kind]} of an uncertainty study of {plate.get('material')} "
        f"{plate.get('thickness_mm')} mm"
    )


def _plate(attributes: Mapping[str, object]) -> dict[str, Any]:
    """The plate object of attributes :func:`_attributes` made."""
    found: dict[str, Any] = json.loads(str(attributes["plate"]))
    return found


def _sampling(spec: Mapping[str, Any]) -> str:
    """How a spec (as described) draws its samples: ``sobol, seed 7``."""
    return f"{spec.get('method')}, seed {spec.get('seed')}"


def _attributes(
    kind: str, spec: UncertaintySpec, simulation: Simulation, searched: bool,
    settings: Mapping[str, Any],
) -> dict[str, object]:  # fmt: skip
    plate = plate_to_dict(spec.plate, registry=simulation.registry)
    return {
        "kind": kind,
        "description": f"{_title(kind, plate)}; see docs/uncertainty.md",
        "spec": json.dumps(spec.describe(), sort_keys=True),
        "spec_sha256": spec_digest(spec),
        "settings": json.dumps(dict(settings), sort_keys=True),
        "plate": json.dumps(plate),
        "model": json.dumps(simulation.describe(), sort_keys=True),
        "plugins": json.dumps(code_record(simulation, searched), sort_keys=True),
        "versions": json.dumps(versions(), sort_keys=True),
        "git_commit": git_commit(),
        "host": socket.gethostname(),
        "creation_time": dt.datetime.now(dt.UTC).isoformat(),
    }


def limits_to_record(
    found: Sequence[SampledLimits], simulation: Simulation, settings: Mapping[str, Any]
) -> Record:
    """The sampled ballistic and ricochet limits at each obliquity (rows) and sample
    (columns) [m/s], −inf/+inf where below/beyond the speed range (uncertainty.limits)."""
    first = found[0]
    attributes = _attributes(KIND_LIMITS, first.spec, simulation, True, settings)
    attributes |= {
        "tolerance": first.tolerance, "tolerance_units": "m/s",
        "resolution": first.resolution, "resolution_units": "m/s",
        "scenes": first.scenes, "passes": first.passes,
    }  # fmt: skip
    table = input_table(simulation.registry)
    samples = {
        table[name].column: values * table[name].parameter.scale
        for name, values in first.inputs.items()
    }
    limits = {
        "ballistic_limit": np.array([f.ballistic for f in found]),
        "ricochet_limit": np.array([f.ricochet for f in found]),
        "perforation_gaps": np.array([f.perforation_gaps for f in found]),
        "ricochet_gaps": np.array([f.ricochet_gaps for f in found]),
        "speed_range": np.array(first.speeds),
    }
    columns = limits_columns(
        np.array([f.obliquity for f in found]), limits, samples, simulation.registry,
        _sampling(first.spec.describe()),
    )  # fmt: skip
    return Record(attributes, columns, _title(KIND_LIMITS, _plate(attributes)))


def limits_from_record(
    record: Record, spec: UncertaintySpec, registry: PluginRegistry, what: str
) -> tuple[SampledLimits, ...]:
    """The sampled limits ``record`` holds, of ``spec`` (whose samples are drawn again,
    the same bits, and checked against the stored ones)."""
    attributes = record.attributes
    inputs = sample_inputs(spec)
    table = input_table(registry)
    samples = samples_of(record)
    for name, values in inputs.items():
        if not np.array_equal(samples[table[name].column], values * table[name].parameter.scale):
            raise ArchiveError(f"{what}: its samples of {name} are not the spec's")
    obliquities = grid_data(record, "impact_obliquity")
    shape = (obliquities.size, spec.samples)
    data = limits_data(record)
    ballistic, ricochet = data["ballistic_limit"], data["ricochet_limit"]
    if (
        ballistic.shape != shape
        or ricochet.shape != shape
        or np.isnan(ballistic).any()
        or np.isnan(ricochet).any()
    ):
        raise ArchiveError(f"{what}: its limits are not {shape[0]} x {shape[1]} speeds")
    start, end = (float(x) for x in data["speed_range"])
    return tuple(
        SampledLimits(
            spec,
            float(angle),
            inputs,
            ballistic[k],
            (start, end),
            typed.number(attributes, "tolerance", what),
            typed.number(attributes, "resolution", what),
            ricochet=ricochet[k],
            perforation_gaps=int(data["perforation_gaps"][k]),
            ricochet_gaps=int(data["ricochet_gaps"][k]),
            scenes=int(typed.number(attributes, "scenes", what)),
            passes=int(typed.number(attributes, "passes", what)),
        )  # fmt: skip
        for k, angle in enumerate(obliquities)
    )


def indices_to_record(
    found: Mapping[str, SobolIndices], spec: UncertaintySpec, simulation: Simulation,
    settings: Mapping[str, Any],
) -> Record:  # fmt: skip
    """Each quantity's first-order and total Sobol' indices, with the half-widths of
    their bootstrap intervals (dimensionless)."""
    searched = "ballistic_limit" in found
    attributes = _attributes(KIND_INDICES, spec, simulation, searched, settings)
    for quantity, indices in found.items():
        attributes[f"{quantity}_inputs"] = json.dumps(list(indices.names))
        attributes[f"{quantity}_evaluations"] = indices.evaluations
        attributes[f"{quantity}_confidence"] = indices.confidence
    attributes["quantities"] = json.dumps(list(found))
    names = {indices.names for indices in found.values()}
    if len(names) != 1:
        raise ValueError(f"the quantities' indices are of different inputs: {names}")
    columns = indices_columns(
        names.pop(),
        {q: {key: getattr(indices, key) for key in INDEX_KEYS} for q, indices in found.items()},
    )
    return Record(attributes, columns, _title(KIND_INDICES, _plate(attributes)))


def indices_from_record(record: Record, what: str) -> dict[str, SobolIndices]:
    """The Sobol' indices ``record`` holds, by quantity."""
    attributes = record.attributes
    out = {}
    for quantity in typed.json_value(attributes, "quantities", what, list):
        names = tuple(
            str(n) for n in typed.json_value(attributes, f"{quantity}_inputs", what, list)
        )
        first, first_half, total, total_half = (
            index_data(record, quantity, key)
            for key in ("first", "first_halfwidth", "total", "total_halfwidth")
        )
        if any(a.shape != (len(names),) for a in (first, first_half, total, total_half)):
            raise ArchiveError(
                f"{what}: the indices of {printable(quantity)} are not one per input"
            )
        out[str(quantity)] = SobolIndices(
            names, first, first_half, total, total_half,
            int(typed.number(attributes, f"{quantity}_evaluations", what)),
            typed.number(attributes, f"{quantity}_confidence", what),
        )  # fmt: skip
    return out


def map_to_record(
    found: OutcomeGrid, simulation: Simulation, settings: Mapping[str, Any]
) -> Record:
    """How many samples end in each outcome at each (speed, obliquity) point."""
    attributes = _attributes(KIND_MAP, found.spec, simulation, False, settings)
    attributes["samples"] = found.samples
    columns = map_columns(found.speeds_m_s, np.radians(found.obliquities_deg), found.counts)
    return Record(attributes, columns, _title(KIND_MAP, _plate(attributes)))


def map_from_record(record: Record, spec: UncertaintySpec, what: str) -> OutcomeGrid:
    """The probability map ``record`` holds, of ``spec``."""
    speeds = grid_data(record, "impact_speed")
    # degrees as typed (30, not 29.999999999999996 after the round trip through rad)
    degrees = np.array(
        [float(f"{math.degrees(x):.12g}") for x in grid_data(record, "impact_obliquity")]
    )
    counts = {name: count_data(record, name) for name in OUTCOMES}
    samples = int(typed.number(record.attributes, "samples", what))
    if any(c.shape != (speeds.size, degrees.size) for c in counts.values()) or np.any(
        sum(counts.values()) != samples
    ):
        raise ArchiveError(f"{what}: its counts are not {samples} samples at each point")
    return OutcomeGrid(spec, speeds, degrees, counts, samples)


def _read_back(
    record: Record, what: str, spec: UncertaintySpec, read: Callable[[Record, str], Found]
) -> Found:
    """``read(record, what)`` of a record made for ``spec``; ArchiveError, one line, for
    a record of another spec or one that is damaged (it comes from a file)."""
    with reading(what):
        if typed.text(record.attributes, "spec_sha256", what) != spec_digest(spec):
            raise ArchiveError(f"{what} was made for another spec")
        return read(record, what)


def _columns(record: Record, what: str, registry: PluginRegistry) -> dict[str, RecordColumn]:
    """The columns of a stored record of an uncertainty study (either layout), as
    :func:`limits_to_record`, :func:`indices_to_record` or :func:`map_to_record` make
    them."""
    attributes = record.attributes
    kind = typed.text(attributes, "kind", what)
    if kind == KIND_LIMITS:
        return limits_columns(
            grid_data(record, "impact_obliquity"), limits_data(record), samples_of(record),
            registry, _sampling(typed.json_value(attributes, "spec", what, dict)),
        )  # fmt: skip
    if kind == KIND_INDICES:
        quantities = typed.json_value(attributes, "quantities", what, list)
        names = {json.dumps(typed.json_value(attributes, f"{q}_inputs", what, list))
                 for q in quantities}  # fmt: skip
        if len(names) != 1:
            raise ValueError("its quantities' indices are of different inputs")
        return indices_columns(
            [str(n) for n in json.loads(names.pop())],
            {q: {key: index_data(record, q, key) for key in INDEX_KEYS} for q in quantities},
        )
    return map_columns(
        grid_data(record, "impact_speed"), grid_data(record, "impact_obliquity"),
        {name: count_data(record, name) for name in OUTCOMES},
    )  # fmt: skip


def cf_record(record: Record, what: str, registry: PluginRegistry) -> Record:
    """The stored ``record`` of an uncertainty study (either layout) as this plateimpact
    writes it: its attributes as stored, its columns over their dimensions (export)."""
    with reading(what):
        kind = typed.text(record.attributes, "kind", what)
        title = _title(kind, typed.json_value(record.attributes, "plate", what, dict))
        return Record(record.attributes, _columns(record, what, registry), title)


#: Each kind's :func:`cf_record`, for ``plateimpact export --record``.
CF_RECORDS = {kind: cf_record for kind in SHORT}


def read_stored(
    archive: Archive | str, name: str, spec: UncertaintySpec, registry: PluginRegistry
) -> tuple[SampledLimits, ...] | dict[str, SobolIndices] | OutcomeGrid:
    """The sampled limits, Sobol' indices (by quantity) or probability map stored as
    ``name`` for ``spec``, as they were computed."""
    where = archive if isinstance(archive, Archive) else Archive(archive)
    record = where.record(name)
    what = f"archive {where.path}: {LIMITS}/{printable(name)}"
    kind = typed.text(record.attributes, "kind", what)
    readers: dict[str, Callable[[Record, str], Any]] = {
        KIND_LIMITS: lambda r, w: limits_from_record(r, spec, registry, w),
        KIND_INDICES: indices_from_record,
        KIND_MAP: lambda r, w: map_from_record(r, spec, w),
    }
    if kind not in readers:
        raise ArchiveError(f"{what} is {printable(kind, 40)}, not a result of an uncertainty study")
    found: tuple[SampledLimits, ...] | dict[str, SobolIndices] | OutcomeGrid = _read_back(
        record, what, spec, readers[kind]
    )
    return found


def kept_or_computed(
    archive: Archive | None,
    name: str,
    *,
    resume: bool,
    code: Mapping[str, Any],
    spec: UncertaintySpec,
    compute: Callable[[], Found],
    to_record: Callable[[Found], Record],
    from_record: Callable[[Record, str], Found],
) -> Found:
    """``compute()`` and store its record as ``name`` in ``archive`` (if any); with
    ``resume``, the stored record read back instead when it is there, made by the same
    ``code`` for the same spec. Without ``resume`` a stored one is refused before
    anything is computed (RecordExistsError)."""
    if archive is None:
        return compute()
    archive.check_writable()
    what = f"archive {archive.path}: {LIMITS}/{name}"
    if archive.real.exists() and name in archive.limits_names():
        if not resume:
            raise RecordExistsError(
                f"archive {archive.path} already has this result of this spec ({LIMITS}/"
                f"{name}): read it back with resume (--resume), or use another archive"
            )
        record = archive.record(name)
        try:
            check_code(what, record.attributes.get("plugins"), code)
        except StaleRunError as exc:  # a stored result is never replaced
            raise RecordExistsError(f"{exc.what}; store into another archive") from None
        return _read_back(record, what, spec, from_record)
    found = compute()
    archive.append_record(name, to_record(found))
    return found
