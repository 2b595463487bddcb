"""How archives write and check HDF5: checksummed datasets with units, sealed attributes,
ragged arrays (docs/archive.md)."""

from __future__ import annotations

import hashlib
import json

import h5py
import numpy as np

from ..base.parameters import Parameter
from ..model.ragged import Ragged

#: Attribute holding the SHA-256 of a study's, run's or stored record's other attributes.
SEAL = "attributes_sha256"


def write_dataset(
    group: h5py.Group,
    name: str,
    data: np.ndarray,
    units: str,
    description: str,
    long_name: str | None = None,
) -> None:
    """A chunked, fletcher32-checksummed dataset with ``units`` and ``description`` (and
    ``long_name``, if given). 1-D unless ``data`` has more dimensions (an outcome map's
    grid), which are chunked whole up to 2**16 values."""
    data = np.asarray(data)
    if data.ndim <= 1:
        chunk: tuple[int, ...] = (int(min(max(data.size, 1), 1 << 16)),)
    else:
        rows = max(1, (1 << 16) // max(int(np.prod(data.shape[1:])), 1))
        chunk = (min(max(data.shape[0], 1), rows), *(max(n, 1) for n in data.shape[1:]))
    maxshape = (None,) * max(data.ndim, 1)
    ds = group.create_dataset(name, data=data, chunks=chunk, maxshape=maxshape, fletcher32=True)
    ds.attrs["units"] = units
    if long_name is not None:
        ds.attrs["long_name"] = long_name
    ds.attrs["description"] = description


def write_declared(group: h5py.Group, declared: Parameter, data: np.ndarray) -> None:
    """A dataset of a declared quantity: its SI unit ("1" for none) and description."""
    write_dataset(group, declared.name, data, declared.unit or "1", declared.description)


def plain_attributes(group: h5py.Group) -> dict[str, object]:
    """The group's attributes as Python values, without netCDF's own (``_NCProperties``,
    which the netCDF library may write or rewrite). netCDF stores a number as an array of
    one; it reads back as the number."""
    return {
        k: v.item() if isinstance(v, np.generic) or np.ndim(v) == 1 and np.size(v) == 1 else v
        for k, v in group.attrs.items()
        if not k.startswith("_")
    }


def digest(attributes: dict[str, object]) -> str:
    text = json.dumps({k: attributes[k] for k in sorted(attributes)}, sort_keys=True)
    return hashlib.sha256(text.encode()).hexdigest()


def seal(group: h5py.Group) -> None:
    """Store the digest of the group's attributes (checked on reading)."""
    attributes = plain_attributes(group)
    attributes.pop(SEAL, None)
    group.attrs[SEAL] = digest(attributes)


def write_ragged(
    group: h5py.Group,
    ragged: Ragged,
    counts: str,
    sample_dimension: str,
    declared: dict[str, Parameter],
) -> None:
    """A CF contiguous ragged array: ``counts`` per row, then every column (units and
    descriptions from ``declared``, by column name)."""
    group.attrs["layout"] = f"contiguous ragged array (CF): {counts} gives each scene's samples"
    write_dataset(group, counts, ragged.counts, "1", "samples per scene, in scene order")
    group[counts].attrs["sample_dimension"] = sample_dimension
    for name, values in [*ragged.values.items(), *ragged.per_row.items()]:
        write_declared(group, declared[name], values)
