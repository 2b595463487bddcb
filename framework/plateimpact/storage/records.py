"""Stored records: named results other than runs, kept in an archive beside its studies
(docs/archive.md, "Limits and outcome maps").

A record is plain data, so that storage needs nothing of what it holds: sealed
attributes (strings and numbers) and columns, each with its SI ``units``, a
``long_name``, a ``description`` and the named dimensions it runs over. Records live
under the top-level group ``/limits``, one entry each, ``/limits/NAME`` (format 2: a
link to the record's own data file, as runs are); a name already there gets ``.2``,
``.3``, ..., and the name it took is returned and printed. The study name ``limits`` is
therefore reserved.

A record's data file is netCDF-4 and CF-1.11 (storage.netcdf): one flat group, every
column a variable over its dimensions, each dimension with its coordinate variable (so
the file holds no dataset but the columns), the attributes global and sealed, with
``Conventions``, ``title`` and ``history``. Records written before that are HDF5 groups
whose columns are datasets at paths (``lines/fixed``) without dimensions; they are read
as they are (:func:`stored` finds a column under either name).
"""

from __future__ import annotations

import contextlib
from collections.abc import Callable, Iterator, Mapping
from pathlib import Path
from typing import BinaryIO

import attrs
import h5py
import numpy as np

from ..base.errors import ArchiveError, ParameterError, PlateImpactError
from ..base.untrusted import printable
from .append import append_with
from .data_files import DataFiles
from .hdf5 import seal
from .netcdf import Flags, cf_variable, described, seal_file

#: The top-level group of the stored records; a study may not take its name.
LIMITS = "limits"
#: Entry names that an older plateimpact, which takes ``/limits`` for a study, would
#: misread as that study's groups.
RESERVED_NAMES = ("runs", "scenes")


@attrs.frozen(eq=False)
class RecordColumn:
    """One variable of a record: ``data`` [``units``, SI; "1" for none] over the named
    ``dimensions`` (one per axis of ``data``), with CF ``flags`` (codes and their names)
    for integer codes and the CF ``coordinates`` (auxiliary coordinates' names, blank
    separated) that label it. Read back, a column has its data only
    (storage.records.read_record)."""

    data: np.ndarray
    units: str
    long_name: str
    description: str = ""
    dimensions: tuple[str, ...] = ()
    flags: Flags | None = None
    coordinates: str = ""


@attrs.frozen(eq=False)
class Record:
    """What a record stores: ``attributes`` (str, int, float or bool; sealed) and
    ``columns`` by their variable's name (in a record read back from before records
    were netCDF, by their path: ``lines/fixed``); ``what``: what it holds, for the
    file's ``title`` and ``history`` (read back, the ``title`` attribute says it)."""

    attributes: dict[str, object]
    columns: dict[str, RecordColumn]
    what: str = ""


def index_column(dimension: str, size: int, what: str) -> RecordColumn:
    """The coordinate variable of ``dimension``: each ``what``'s index, from 0."""
    return RecordColumn(
        np.arange(size, dtype=np.int64), "1", f"{dimension} index",
        f"the {what}'s index, from 0", (dimension,),
    )  # fmt: skip


def stored(record: Record, name: str, legacy: str) -> np.ndarray:
    """The data of the column ``name``, or of ``legacy`` (its path in a record written
    before records were netCDF); KeyError if the record has neither."""
    column = record.columns.get(name, record.columns.get(legacy))
    if column is None:
        raise KeyError(name)
    return column.data


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


@contextlib.contextmanager
def reading(what: str) -> Iterator[None]:
    """Turn what reading a record's values may raise (a record comes from a file, maybe
    someone else's: a column missing, of the wrong shape or type) into one
    ArchiveError naming ``what``."""
    try:
        yield
    except ArchiveError:
        raise
    except (KeyError, ValueError, TypeError, IndexError, AttributeError, PlateImpactError) as exc:
        reason = printable(str(exc).splitlines()[0] if str(exc) else "missing", 160)
        raise ArchiveError(
            f"{what} cannot be read back ({type(exc).__name__}: {reason}); the record is damaged"
        ) from None


def _dimension_sizes(columns: Mapping[str, RecordColumn]) -> dict[str, int]:
    """Each dimension the ``columns`` run over and its size; ValueError unless every
    column names one dimension per axis (at least one: checksums need chunks), each
    dimension has one size and a coordinate variable (a column of its name over it)."""
    sizes: dict[str, int] = {}
    for name, column in columns.items():
        shape = np.shape(column.data)
        if not column.dimensions or len(column.dimensions) != len(shape):
            raise ValueError(f"column {name}: {len(shape)} axes, dimensions {column.dimensions}")
        for dimension, size in zip(column.dimensions, shape, strict=True):
            if sizes.setdefault(dimension, size) != size:
                raise ValueError(f"column {name}: {dimension} has size {sizes[dimension]}")
    for dimension in sizes:
        if dimension not in columns or columns[dimension].dimensions != (dimension,):
            raise ValueError(f"dimension {dimension} has no coordinate variable")
    return sizes


def write_record_file(where: BinaryIO, record: Record) -> None:
    """The record's own netCDF-4 file (into a file object: archives write in memory):
    its dimensions, coordinate variables first, then the other columns, and the sealed
    global attributes with ``Conventions``, ``title`` and ``history``."""
    import h5netcdf  # noqa: PLC0415 (only archives need it)

    sizes = _dimension_sizes(record.columns)
    first = sorted(record.columns, key=lambda name: name not in sizes)
    with h5netcdf.File(where, "w") as f:
        f.dimensions.update(sizes)
        for name in first:
            column = record.columns[name]
            variable = cf_variable(
                f, name, column.dimensions, column.data, units=column.units,
                long_name=column.long_name, description=column.description,
                flags=column.flags,
            )  # fmt: skip
            if column.coordinates:
                variable.attrs["coordinates"] = column.coordinates
        what = record.what or f"stored {record.attributes.get('kind', 'record')}"
        seal_file(f, {**described(what, record.attributes), **record.attributes})


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
