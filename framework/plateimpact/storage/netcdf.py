"""The data files of a format-2 archive: one netCDF-4 file per run and per study's scenes
(docs/archive.md). xarray opens a run file as it is, with no project code:

    xarray.open_dataset(run_file, engine="h5netcdf")

gives one Dataset whose variables share the dimension ``scene``, with the scene's
parameters (impact speed, obliquity, sphere, plate label and constants) as coordinates,
CF ``units``/``long_name`` on every variable and ``flag_values``/``flag_meanings`` on the
outcome. Trajectories and crater sections are CF contiguous ragged arrays
(``trajectory_count`` with ``sample_dimension = "trajectory_sample"``; ``crater_count``
with ``"crater_point"``). Every dataset is fletcher32-checksummed; the file's global
attributes are sealed by their SHA-256 as in format 1.
"""

from __future__ import annotations

import math
import os
from collections.abc import Mapping, Sequence
from typing import Any, BinaryIO

import h5py
import numpy as np

from ..base.errors import ArchiveError
from ..base.parameters import Parameter
from ..base.untrusted import load_json
from ..model.ragged import Ragged
from ..model.results import CRATER_FIELDS, RESULT_FIELDS, TRAJECTORY_FIELDS, BatchResult
from ..model.tables import CONVENTIONS, FLAGS, PLATE, SCENE, SCENE_INDEX, long_name
from .hdf5 import digest

SAMPLE, POINT = "trajectory_sample", "crater_point"


#: CF flags: the codes (``flag_values``) and their blank-separated names.
Flags = tuple[Sequence[int], str]


def _chunks(shape: tuple[int, ...]) -> tuple[int, ...]:
    """Whole rows up to 2**16 values a chunk (a grid's rows whole)."""
    inner = math.prod(max(n, 1) for n in shape[1:])
    rows = max(1, (1 << 16) // inner)
    return (int(min(max(shape[0], 1), rows)), *(max(n, 1) for n in shape[1:]))


def cf_variable(
    f: Any, name: str, dims: tuple[str, ...], data: np.ndarray, *, units: str, long_name: str,
    description: str, flags: Flags | None = None,
) -> Any:  # fmt: skip
    """A variable over ``dims`` (at least one: HDF5 checksums chunked data only), numbers
    chunked and fletcher32-checksummed with CF ``units`` ("1": dimensionless), text
    without; ``long_name``, ``description`` and, for integer codes, CF ``flags``."""
    data = np.asarray(data)
    if data.dtype == bool:
        data = data.astype(np.int8)
    if data.dtype.kind in "OUS":
        variable = f.create_variable(name, dims, h5py.string_dtype(), data=data.astype(object))
    else:
        variable = f.create_variable(
            name, dims, data.dtype, data=data, chunks=_chunks(data.shape), fletcher32=True
        )
    if flags is not None:
        variable.attrs["flag_values"] = np.array(flags[0], dtype=data.dtype)
        variable.attrs["flag_meanings"] = flags[1]
    if data.dtype.kind not in "OUS":
        variable.attrs["units"] = units or "1"
    variable.attrs["long_name"] = long_name
    variable.attrs["description"] = description
    return variable


def _variable(
    f: Any, name: str, dims: tuple[str, ...], data: np.ndarray, declared: Parameter
) -> Any:
    """:func:`cf_variable` of a declared quantity (its SI unit, its flags if coded)."""
    return cf_variable(
        f, name, dims, data, units=declared.unit, long_name=long_name(declared),
        description=declared.description, flags=FLAGS.get(declared.name),
    )  # fmt: skip


def write_scenes(
    f: Any,
    columns: Mapping[str, np.ndarray],
    declared: Mapping[str, Parameter],
    plate_labels: Sequence[str],
) -> list[str]:
    """The ``scene`` dimension and its coordinates (every scene column [SI], then the
    plate's label); returns the coordinates' names, for the data variables' CF
    ``coordinates`` attribute."""
    size = len(plate_labels)
    f.dimensions[SCENE] = size
    _variable(f, SCENE, (SCENE,), np.arange(size, dtype=np.int64), SCENE_INDEX)
    for name, values in columns.items():
        _variable(f, name, (SCENE,), values, declared[name])
    _variable(f, PLATE.name, (SCENE,), np.array(list(plate_labels), dtype=object), PLATE)
    return [*columns, PLATE.name]


def write_ragged(
    f: Any, prefix: str, dimension: str, ragged: Ragged, declared: Mapping[str, Parameter]
) -> None:
    """A CF contiguous ragged array: ``PREFIX_count`` per scene, then the columns as
    ``PREFIX_NAME`` over ``dimension`` (per-scene ones over ``scene``)."""
    f.dimensions[dimension] = int(ragged.counts.sum())
    counts = Parameter(f"{prefix}_count", f"{dimension.replace('_', ' ')}s per scene, in order")
    count = _variable(f, counts.name, (SCENE,), ragged.counts.astype(np.int64), counts)
    count.attrs["sample_dimension"] = dimension
    for name, values in ragged.values.items():
        _variable(f, f"{prefix}_{name}", (dimension,), values, declared[name])
    for name, values in ragged.per_row.items():
        _variable(f, f"{prefix}_{name}", (SCENE,), values, declared[name])


def trajectory_field(name: str, state_units: Mapping[str, str]) -> Parameter:
    """The declaration of a trajectory column: a core one or ``failure_<state>``."""
    if name in TRAJECTORY_FIELDS:
        return TRAJECTORY_FIELDS[name]
    state = name.removeprefix("failure_")
    return Parameter(
        name, f"failure-model state {state!r} (NaN before failure)", state_units.get(state, "1")
    )


def write_run_file(
    path: str | os.PathLike[str] | BinaryIO,
    columns: Mapping[str, np.ndarray],
    declared: Mapping[str, Parameter],
    plate_labels: Sequence[str],
    result: BatchResult,
    attributes: Mapping[str, object],
) -> None:
    """One run as a netCDF-4 file at ``path`` (a file object: archives write in memory):
    the scenes as coordinates, the results as variables over ``scene``, the ragged
    arrays, and ``attributes`` (sealed; ``failure_state_units`` may come from an archive,
    so it is read as untrusted JSON)."""
    import h5netcdf  # noqa: PLC0415 (only archives need it)

    with h5netcdf.File(path, "w") as f:
        coordinates = " ".join(write_scenes(f, columns, declared, plate_labels))
        for name, field in RESULT_FIELDS.items():
            variable = _variable(f, name, (SCENE,), result.columns[name], field)
            variable.attrs["coordinates"] = coordinates
        if result.trajectory is not None:
            units = load_json(
                str(attributes.get("failure_state_units", "{}")),
                "attribute failure_state_units",
                ArchiveError,
            )
            if not isinstance(units, dict) or not all(isinstance(u, str) for u in units.values()):
                raise ArchiveError("attribute failure_state_units is not an object of unit names")
            fields = {k: trajectory_field(k, units) for k in result.trajectory.values}
            write_ragged(f, "trajectory", SAMPLE, result.trajectory, fields)
            # CF §9: paths in time stored as a contiguous ragged array are a discrete
            # sampling geometry, one trajectory per scene, identified by the scene
            f.variables[SCENE].attrs["cf_role"] = "trajectory_id"
            feature = {"featureType": "trajectory"}
        else:
            feature = {}
        if result.craters is not None:
            write_ragged(f, "crater", POINT, result.craters, CRATER_FIELDS)
        what = f"run {attributes.get('study')}/{attributes.get('run')}"
        seal_file(f, {**described(what, attributes), **feature, **attributes})


def write_scenes_file(
    path: str | os.PathLike[str] | BinaryIO,
    columns: Mapping[str, np.ndarray],
    declared: Mapping[str, Parameter],
    plate_labels: Sequence[str],
    attributes: Mapping[str, object],
) -> None:
    """A study's scenes as a netCDF-4 file: the ``scene`` coordinates only."""
    import h5netcdf  # noqa: PLC0415

    with h5netcdf.File(path, "w") as f:
        write_scenes(f, columns, declared, plate_labels)
        seal_file(f, {**described(f"scenes of study {attributes.get('study')}", attributes),
                      **attributes})  # fmt: skip


def described(what: str, attributes: Mapping[str, object]) -> dict[str, str]:
    """A data file's ``Conventions``, ``title`` and ``history`` (CF §2.6.2): what it holds
    and, for a run, when it started (a stored record: when it was made; a study's scenes
    file carries no time, so that writing the same study twice gives the same file)."""
    when = attributes.get("start_time", attributes.get("creation_time"))
    return {
        "Conventions": CONVENTIONS,
        "title": f"plateimpact {what}: rigid spheres striking plates (model of NWC TP 5844)",
        "history": f"{when + ': ' if isinstance(when, str) else ''}{what} computed and "
        "written by plateimpact",
    }


def seal_file(f: Any, attributes: Mapping[str, object]) -> None:
    """Global attributes and their digest (netCDF's own ``_``-attributes aside)."""
    for key, value in attributes.items():
        f.attrs[key] = value
    f.attrs["attributes_sha256"] = digest(dict(attributes))
