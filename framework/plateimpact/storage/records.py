"""Stored records: named results other than runs, kept in an archive beside its studies
(docs/archive.md, "Limits and outcome maps").

A record is plain data, so that storage needs nothing of what it holds: sealed
attributes (strings and numbers) and datasets, each with its SI ``units``, a
``long_name`` and a ``description``. Records live under the top-level group ``/limits``,
one entry each, ``/limits/NAME`` (format 2: a link to the record's own data file, as
runs are); a name already there gets ``.2``, ``.3``, ..., and the name it took is
returned and printed. The study name ``limits`` is therefore reserved.
"""

from __future__ import annotations

from collections.abc import Callable
from pathlib import Path
from typing import BinaryIO

import attrs
import h5py
import numpy as np

from ..base.errors import ArchiveError, ParameterError
from ..base.untrusted import printable
from .append import append_with
from .data_files import DataFiles
from .hdf5 import seal, write_dataset

#: The top-level group of the stored records; a study may not take its name.
LIMITS = "limits"
#: Entry names that an older plateimpact, which takes ``/limits`` for a study, would
#: misread as that study's groups.
RESERVED_NAMES = ("runs", "scenes")


@attrs.frozen(eq=False)
class RecordColumn:
    """One dataset of a record: ``data`` [``units``, SI; "1" for none]. Read back, a
    column has its data only (storage.records.read_record)."""

    data: np.ndarray
    units: str
    long_name: str
    description: str = ""


@attrs.frozen(eq=False)
class Record:
    """What a record stores: ``attributes`` (str, int, float or bool; sealed) and
    ``columns`` by their path inside the record's group (``lines/fixed``)."""

    attributes: dict[str, object]
    columns: dict[str, RecordColumn]


def is_container(f: h5py.File, name: str) -> bool:
    """Whether the top-level group ``name`` holds records rather than a study (an archive
    written before records were stored may hold a study named ``limits``)."""
    return name == LIMITS and "scenes" not in f[name]


def study_names(f: h5py.File) -> list[str]:
    """The archive's studies: its top-level groups but the records' one (anything else
    at the top, or a study whose runs are not a group, is damage)."""
    names = []
    for name in f:
        if not isinstance(f.get(name), h5py.Group):
            raise ArchiveError(
                f"{f.filename}: /{printable(name, 80)} is not a group; the archive is damaged"
            )
        if not is_container(f, name):
            runs = f[name].get("runs")
            if runs is not None and not isinstance(runs, h5py.Group):
                raise ArchiveError(
                    f"{f.filename}: /{printable(name, 80)}/runs is not a group; the archive "
                    "is damaged"
                )
            names.append(name)
    return names


def check_study_name(name: str, path: Path) -> None:
    if name == LIMITS:
        raise ArchiveError(
            f"archive {path}: the study name {LIMITS!r} is reserved for stored limits and "
            "maps; rename the study"
        )


def check_record_name(name: object) -> str:
    """A record's requested name: printable, no '/', no surrounding space, not one an
    older reader would misread."""
    text = name if isinstance(name, str) else ""
    if not text or text != text.strip() or "/" in text or not text.isprintable():
        raise ParameterError(
            "name", f"name must be a printable name without '/' or surrounding space, got {name!r}"
        )
    if text in RESERVED_NAMES:
        raise ParameterError(
            "name",
            f"name {text!r} is reserved (an older plateimpact would misread it); "
            f"any other name, but not {' or '.join(RESERVED_NAMES)}",
        )
    return text


def write_record(
    f: h5py.File, files: DataFiles, name: str, record: Record, path: Path, overwrite: bool = False
) -> str:
    """Add ``record`` to the index ``f`` as ``/limits/NAME`` (``NAME.2``, ... if taken;
    with ``overwrite`` it replaces ``NAME``), its data in a file of its own; returns the
    name it was stored under."""
    if LIMITS in f and not is_container(f, LIMITS):
        raise ArchiveError(
            f"archive {path} holds a study named {LIMITS!r}, where limits are stored; "
            "store them in another archive"
        )
    if LIMITS not in f:
        container = f.create_group(LIMITS, track_order=True)
        container.attrs["description"] = (
            "stored limits and outcome maps, one entry each; see docs/archive.md"
        )
        seal(container)
    container = f[LIMITS]
    stored, k = name, 1
    if not isinstance(container, h5py.Group):
        raise ArchiveError(f"archive {path}: /{LIMITS} is not a group; the archive is damaged")
    if overwrite and name in container:
        old = container.get(name, getlink=True)
        if isinstance(old, h5py.ExternalLink):
            files.retire(old.filename)
        del container[name]
    while stored in container:
        k += 1
        stored = f"{name}.{k}"
    target = files.new(f"{LIMITS}.{stored}", lambda handle: write_record_file(handle, record))
    container[stored] = h5py.ExternalLink(target, "/")
    return stored


def write_record_file(where: BinaryIO, record: Record) -> None:
    """The record's own HDF5 file (into a file object: archives write in memory): sealed
    attributes at its root, then its datasets."""
    with h5py.File(where, "w") as group:
        for key, value in record.attributes.items():
            group.attrs[key] = value
        seal(group)
        for at, column in record.columns.items():
            parent, _, leaf = at.rpartition("/")
            target = group.require_group(parent) if parent else group
            write_dataset(
                target, leaf, column.data, column.units, column.description, column.long_name
            )


def append_record(
    real: Path, name: str, record: Record, path: Path, overwrite: bool = False
) -> str:
    """Add ``record`` to the archive ``real`` through the atomic append (storage.append:
    its data file, then the index copied, extended and replaced, each stage a fault
    point); ``path`` as the user named the archive, for messages. The caller holds the
    lock."""
    return append_with(real, lambda f, files: write_record(f, files, name, record, path, overwrite))


def record_names(f: h5py.File) -> list[str]:
    """The records of the open index ``f``, in the order written."""
    if LIMITS not in f or not is_container(f, LIMITS):
        return []
    group = f[LIMITS]
    if f.attrs.get("format_version") != 1:
        return list(group)  # links kept in the order made
    return sorted(group, key=lambda name: str(group[name].attrs.get("creation_time", "")))


def read_record(
    group: h5py.Group,
    check_seal: Callable[[h5py.Group], dict[str, object]],
    read: Callable[[str], np.ndarray],
) -> Record:
    """The record in ``group``: its attributes through ``check_seal`` (the digest
    checked), every dataset through ``read`` (by its path in the file). The datasets'
    own attributes (units, names) are for readers without plateimpact and are not read
    back: the record's kind says its units, and an attribute in a damaged object header
    can crash the HDF5 library itself, where no error can be caught (found by fuzzing)."""
    attributes = check_seal(group)
    found: list[str] = []

    def visit(name: str, item: object) -> None:
        if isinstance(item, h5py.Dataset):
            found.append(name)

    group.visititems(visit)
    return Record(
        attributes, {where: RecordColumn(read(group[where].name), "", "") for where in found}
    )
