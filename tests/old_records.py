"""Stored records as plateimpact wrote them before records were netCDF (up to commit
a5f04ec): plain HDF5 groups, each column a dataset at a path (``lines/fixed``,
``map/regime``, ``samples/<column>``) with no dimensions, chunked and
fletcher32-checksummed with ``units``, ``long_name`` and ``description``, the
attributes at the root sealed by their digest (no ``Conventions``, ``title`` or
``history``). :func:`to_old_layout` rewrites a record's data file that way, so that a
test can read an old record made here rather than only the one of tests/data."""

from __future__ import annotations

from pathlib import Path

import h5py
import numpy as np

from plateimpact.storage.hdf5 import plain_attributes, seal

#: The coordinate variables of the dimensions netCDF added (no column before).
INDICES = {"line", "boundary", "sphere", "plate", "obliquity", "sample", "bound", "input",
           "speed", "input_name"}  # fmt: skip
#: Limits' and maps' columns whose paths were not ``GROUP/NAME`` by a prefix.
LIMITS_PATHS = {"line_start": "lines/start", "line_end": "lines/end", "first_regime": "lines/first",
                "regime_below": "boundaries/below", "regime_above": "boundaries/above",
                "regime": "map/regime", "exit_speed": "map/exit_speed",
                "exit_obliquity": "map/exit_obliquity"}  # fmt: skip
NAMED = ("ballistic_limit", "lowest_perforation", "ricochet_limit", "critical_ricochet_obliquity")


def old_paths(name: str, attributes: dict[str, object]) -> list[str]:
    """Where the old layout kept the column ``name`` of a record of these attributes."""
    kind, axis = attributes["kind"], attributes.get("axis")
    if name in INDICES:
        return []
    if str(kind).startswith("uncertainty"):
        if name in ("impact_obliquity", "impact_speed"):
            return ["obliquities" if name == "impact_obliquity" else "speeds"]
        if name.startswith("sampled_"):
            return [f"samples/{name.removeprefix('sampled_')}"]
        if name.endswith("_count"):
            return [f"counts/{name.removesuffix('_count')}"]
        for key in ("first_halfwidth", "total_halfwidth", "first", "total"):
            if name.endswith(f"_{key}"):
                return [f"{name.removesuffix(f'_{key}')}/{key}"]
        return [name]
    fixed = "impact_obliquity" if axis == "impact_speed" else "impact_speed"
    if kind == "outcome_map" and name in ("impact_obliquity", "impact_speed"):
        return ["lines/fixed", "map/obliquities"] if name == fixed else ["map/speeds"]
    if name == fixed:
        return ["lines/fixed"]
    if name in NAMED:
        return [f"lines/{name}"]
    if name in LIMITS_PATHS:
        return [LIMITS_PATHS[name]]
    group, _, leaf = name.partition("_")  # boundary_low, sphere_mass, plate_a
    return [f"{'boundaries' if group == 'boundary' else group}/{leaf}"]


def to_old_layout(path: Path) -> None:
    """Rewrite the record's data file at ``path`` in the layout before netCDF."""
    with h5py.File(path, "r") as f:
        attributes = plain_attributes(f)
        columns = {
            name: (f[name][()], {k: f[name].attrs[k] for k in ("units", "long_name",
                                                               "description")
                                 if k in f[name].attrs})
            for name in f
        }  # fmt: skip
    for key in ("Conventions", "title", "history", "attributes_sha256"):
        attributes.pop(key)
    with h5py.File(path, "w") as group:
        for key, value in attributes.items():
            group.attrs[key] = value
        seal(group)
        for name, (data, labels) in columns.items():
            for where in old_paths(name, attributes):
                dataset = group.create_dataset(
                    where, data=data, chunks=tuple(max(n, 1) for n in np.shape(data)),
                    maxshape=(None,) * data.ndim, fletcher32=True,
                )  # fmt: skip
                for key, value in labels.items():
                    dataset.attrs[key] = value
