"""Runs for review outside plateimpact: a grid study as an xarray cube, a run as a
netCDF-4 file or a tidy CSV table (docs/archive.md, "Reviewing archives").

xarray is imported only here, when asked for.
"""

from __future__ import annotations

import math
import os
from collections.abc import Iterator, Mapping, Sequence
from pathlib import Path
from typing import TYPE_CHECKING, Any, BinaryIO

import numpy as np

from ..base.errors import ParameterError
from ..base.parameters import Parameter
from ..model.batch import CORE_COLUMNS
from ..model.results import RESULT_FIELDS, BatchResult, Outcome
from ..registry.plugin_registry import PluginRegistry
from .append import StudyDefinition
from .archive import Archive
from .data_files import encoded
from .netcdf import FLAGS, long_name, write_run_file

if TYPE_CHECKING:
    import xarray

#: The cube's dimensions, outermost first.
CUBE_DIMENSIONS = ("variant", "plate", "impact_obliquity", "impact_speed")


def declared_column(name: str, registry: PluginRegistry) -> Parameter:
    """What a scene column is: a core column, else a plate constant a plug-in of
    ``registry`` declares, else an undeclared number."""
    found = CORE_COLUMNS.get(name) or registry.plate_constants.get(name)
    return found or Parameter(name, f"plate constant {name} (no installed plug-in declares it)")


def _attributes(declared: Parameter) -> dict[str, Any]:
    attributes: dict[str, Any] = {"long_name": long_name(declared)}
    attributes["description"] = declared.description
    if declared.name in FLAGS:
        attributes["flag_values"] = np.array(FLAGS[declared.name][0], dtype=np.int8)
        attributes["flag_meanings"] = FLAGS[declared.name][1]
    attributes["units"] = declared.unit or "1"
    return attributes


def study_cube(
    study: StudyDefinition, runs: Mapping[str, BatchResult], *, registry: PluginRegistry
) -> xarray.Dataset:
    """A grid study's ``runs`` (by name) as one Dataset over (variant, plate,
    impact_obliquity, impact_speed) [SI, CF attributes]; ParameterError if the scenes
    are not one full grid of plate × obliquity × speed with one sphere."""
    import xarray as xr  # noqa: PLC0415

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
            "read its runs scene by scene (Archive.data_file, xarray.open_dataset)",
        )
    coordinates: dict[str, Any] = {
        "variant": ("variant", list(runs)),
        "plate": ("plate", plates),
        "impact_obliquity": (
            "impact_obliquity", obliquities, _attributes(CORE_COLUMNS["impact_obliquity"])
        ),
        "impact_speed": ("impact_speed", speeds, _attributes(CORE_COLUMNS["impact_speed"])),
    }  # fmt: skip
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
        coordinates[name] = ("plate", per_plate, _attributes(declared_column(name, registry)))
    variables: dict[str, Any] = {}
    for name, declared in RESULT_FIELDS.items():
        stack = []
        for run in runs.values():
            values = np.asarray(run.columns[name])
            values = values.astype(np.int8) if values.dtype == bool else values
            cube = np.empty(shape, dtype=values.dtype)
            cube[index] = values
            stack.append(cube)
        variables[name] = (CUBE_DIMENSIONS, np.stack(stack), _attributes(declared))
    return xr.Dataset(
        variables,
        coordinates,
        attrs={"Conventions": "CF-1.11", "study": study.name, "description": study.description},
    )


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
