"""How archives seal and check the attributes of their HDF5 groups and files
(docs/archive.md)."""

from __future__ import annotations

import hashlib
import json

import h5py
import numpy as np

#: Attribute holding the SHA-256 of a study's, run's or stored record's other attributes.
SEAL = "attributes_sha256"


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
