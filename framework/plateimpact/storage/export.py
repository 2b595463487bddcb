"""Runs and records for review outside plateimpact: a grid study as an xarray cube, a
run as a netCDF-4 file or a tidy CSV table, a stored record (limits, a map, an
uncertainty study's result) as a netCDF-4 file (docs/archive.md, "Reviewing archives").

xarray is imported only when a cube is asked for (model.tables).
"""

from __future__ import annotations

import math
import os
from collections.abc import Callable, Iterator, Mapping, Sequence
from pathlib import Path
from typing import TYPE_CHECKING, BinaryIO

import numpy as np

from ..base.errors import ArchiveError, ParameterError
from ..base.parameters import Parameter
from ..base.untrusted import printable
from ..model.fields import CORE_COLUMNS
from ..model.results import RESULT_FIELDS, BatchResult, Outcome
from ..model.tables import PLATE, VARIANT, Column, LabelledTable, column_declaration
from ..registry.plugin_registry import PluginRegistry
from . import stored_attributes as typed
from .append import StudyDefinition
from .archive import Archive
from .data_files import encoded
from .netcdf import write_run_file
from .records import LIMITS, Record, reading, write_record_file

if TYPE_CHECKING:
    import xarray

#: The cube's dimensions, outermost first.
CUBE_DIMENSIONS = ("variant", "plate", "impact_obliquity", "impact_speed")


def declared_column(name: str, registry: PluginRegistry) -> Parameter:
    """What a scene column is: a core column, else a plate constant a plug-in of
    ``registry`` declares, else an undeclared number."""
    return column_declaration(name, registry.plate_constants)


def study_cube(
    study: StudyDefinition, runs: Mapping[str, BatchResult], *, registry: PluginRegistry
) -> xarray.Dataset:
    """A grid study's ``runs`` (by name) as one Dataset over (variant, plate,
    impact_obliquity, impact_speed) [SI, CF attributes]; ParameterError if the scenes
    are not one full grid of plate × obliquity × speed with one sphere."""
    scenes = study.scenes
    columns = scenes.columns
    plates = sorted(set(study.plate_labels))
    obliquities = np.unique(columns["impact_obliquity"])
    speeds = np.unique(columns["impact_speed"])
    index = (
        np.searchsorted(plates, study.plate_labels),
        np.searchsorted(obliquities, columns["impact_obliquity"]),
        np.searchsorted(speeds, columns["impact_speed"]),
    )
    shape = (len(plates), obliquities.size, speeds.size)
    flat = np.ravel_multi_index(index, shape)
    if flat.size != math.prod(shape) or np.unique(flat).size != flat.size:
        raise ParameterError(
            "study",
            f"study {study.name!r} is not a grid of plate x obliquity x speed "
            f"({flat.size} scenes for {' x '.join(map(str, shape))} cells); "
            "read its runs scene by scene (StudyResults.to_dataframe, Archive.data_file)",
        )
    coordinates: dict[str, Column] = {
        VARIANT.name: ((VARIANT.name,), np.array(list(runs), dtype=object), VARIANT),
        PLATE.name: ((PLATE.name,), np.array(plates, dtype=object), PLATE),
        "impact_obliquity": (("impact_obliquity",), obliquities, CORE_COLUMNS["impact_obliquity"]),
        "impact_speed": (("impact_speed",), speeds, CORE_COLUMNS["impact_speed"]),
    }
    plate_index = index[0]
    for name, values in columns.items():
        if name in ("impact_speed", "impact_obliquity"):
            continue
        per_plate = np.full(len(plates), np.nan)
        per_plate[plate_index] = values
        if not np.array_equal(per_plate[plate_index], values):
            raise ParameterError(
                "study", f"study {study.name!r}: {name} varies within a plate; not one cube"
            )
        coordinates[name] = ((PLATE.name,), per_plate, declared_column(name, registry))
    variables: dict[str, Column] = {}
    for name, declared in RESULT_FIELDS.items():
        stack = []
        for run in runs.values():
            values = np.asarray(run.columns[name])
            cube = np.empty(shape, dtype=values.dtype)
            cube[index] = values
            stack.append(cube)
        variables[name] = (CUBE_DIMENSIONS, np.stack(stack), declared)
    attributes = {"study": study.name, "description": study.description}
    return LabelledTable(CUBE_DIMENSIONS, coordinates, variables, attributes).to_xarray()


def write_run_netcdf(
    archive: Archive, run: str, path: Path | BinaryIO, *, registry: PluginRegistry
) -> None:
    """Write ``run`` of ``archive`` as one netCDF-4 file at ``path`` (a path or a file
    object; as the archive's own data file of a run is: scenes as coordinates, CF
    attributes), whatever the archive's format version."""
    run = archive.resolve(run)
    study = archive.study(run.split("/", 1)[0])
    attributes = {k: v for k, v in archive.raw_attributes(run).items()}
    declared = {name: declared_column(name, registry) for name in study.scenes.columns}
    write_run_file(
        path, study.scenes.columns, declared, study.plate_labels, archive.results(run),
        {"study": study.name, "run": run.split("/", 1)[1], **attributes},
    )  # fmt: skip


def netcdf_bytes(archive: Archive, run: str, *, registry: PluginRegistry) -> bytes:
    """The netCDF-4 file of :func:`write_run_netcdf`, made in memory (libhdf5 writes to
    no disk: no temporary directory that could be full), as bytes for an atomic
    writer."""
    return encoded(lambda handle: write_run_netcdf(archive, run, handle, registry=registry))


def record_netcdf_bytes(
    archive: Archive,
    name: str,
    convert: Mapping[str, Callable[[Record, str, PluginRegistry], Record]],
    *,
    registry: PluginRegistry,
) -> bytes:
    """The stored record ``name`` (``NAME`` or ``limits/NAME``) as one netCDF-4 file, made
    in memory: laid out as the archive writes a record now, whatever layout it was
    stored in (``convert[kind](record, what, registry)`` gives it again from what was
    read; its attributes as stored). UnknownNameError lists the stored names."""
    record = archive.record(name)
    what = f"archive {archive.path}: {LIMITS}/{printable(name.removeprefix(f'{LIMITS}/'))}"
    kind = typed.text(record.attributes, "kind", what)
    if kind not in convert:
        raise ArchiveError(
            f"{what} is of kind {printable(kind, 40)}, which this plateimpact does not "
            f"export (it exports {', '.join(convert)})"
        )
    with reading(what):  # columns that do not agree (a damaged record) are refused too
        again = convert[kind](record, what, registry)
        return encoded(lambda handle: write_record_file(handle, again))


def table_header(archive: Archive, run: str, *, registry: PluginRegistry) -> list[str]:
    """The tidy table's columns: plate, every scene column and result, units in the
    names (user units: mm, g, m/s, deg)."""
    study = archive.study(archive.resolve(run).split("/", 1)[0])
    scene = [declared_column(name, registry).key for name in study.scenes.columns]
    return ["plate", *scene, *(field.key for field in RESULT_FIELDS.values())]


def table_rows(
    archive: Archive, run: str, *, registry: PluginRegistry
) -> Iterator[Sequence[object]]:
    """One row per scene, in the units of :func:`table_header` (outcome by name)."""
    run = archive.resolve(run)
    study = archive.study(run.split("/", 1)[0])
    result = archive.results(run)
    scene = [
        np.asarray(values) / declared_column(name, registry).scale
        for name, values in study.scenes.columns.items()
    ]
    fields: list[Sequence[object]] = []
    for name, field in RESULT_FIELDS.items():
        values = np.asarray(result.columns[name])
        if name == "outcome":
            fields.append([Outcome(int(code)).label for code in values])
        elif values.dtype == bool:
            fields.append([bool(v) for v in values])
        else:
            fields.append(list(values / field.scale))
    for i, label in enumerate(study.plate_labels):
        yield [label, *(float(c[i]) for c in scene), *(f[i] for f in fields)]


def export_path_kind(path: str | os.PathLike[str]) -> str:
    """``"netcdf"`` or ``"csv"`` by the name's suffix; ParameterError otherwise."""
    suffix = Path(path).suffix.lower()
    if suffix == ".nc":
        return "netcdf"
    if suffix == ".csv":
        return "csv"
    raise ParameterError(
        "to", f"--to: end the file name with .nc (netCDF-4) or .csv (a table), got {path!r}"
    )
