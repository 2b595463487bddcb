"""What an HDF5 file of an archive may hold: nothing that reaches other files.

HDF5 can make a file read another one: an external link (``h5py.ExternalLink``) names
an object in another file, a dataset with external raw storage (``dataset.external``)
reads its bytes from other files, a virtual dataset (``dataset.is_virtual``) from
datasets of other files; a soft link makes one name stand for another. An archive from
someone else could use any of them to make plateimpact read, copy (``export``,
``upgrade``) or follow whatever it names. So every file of an archive is checked when
it is opened, before anything in it is read (:func:`check_contained`): only hard links,
no external or virtual storage, and in a format-2 index external links only where the
format puts them (a study's ``scenes``, its ``runs/RUN``, ``limits/NAME``), each naming
a data file of the archive's own pattern (storage.confined.data_file_name).
"""

from __future__ import annotations

import contextlib
import os
from collections.abc import Callable, Iterator
from pathlib import Path

import h5py
from h5py import h5d, h5l, h5o

from ..base.errors import ArchiveError
from ..base.untrusted import printable
from .confined import Opened, data_file_name, directory, is_hdf5, open_regular

#: The most links a file of an archive may hold (an index of 10**5 runs holds about
#: 2 x 10**5; a run's file about 40); more is not an archive, and is not walked further.
MAX_LINKS = 1_000_000
#: The top-level group of stored records (storage.records.LIMITS).
LIMITS = "limits"


def index_link_allowed(name: str) -> bool:
    """Whether a format-2 index may hold an external link at ``name``."""
    parts = name.split("/")
    if len(parts) == 2:
        return parts[1] == "scenes" or parts[0] == LIMITS
    return len(parts) == 3 and parts[1] == "runs"  # (a study may be named limits)


def check_contained(
    f: h5py.File, what: str, external: Callable[[str], bool] | None = None
) -> set[str]:
    """Refuse (ArchiveError) a file holding what reaches other files: soft links,
    external links (except where ``external(name)`` allows one, whose target must be a
    data file of the archive's own), datasets with external or virtual storage. Returns
    the base names of the data files the allowed external links name. (h5py's low-level
    calls: a format-1 archive of a hundred datasets is checked in a few milliseconds.)"""
    links: list[tuple[bytes, int]] = []
    datasets: list[bytes] = []

    def on_link(name: bytes, info: h5l.LinkInfo) -> int | None:
        if info.type != h5l.TYPE_HARD:
            links.append((name, info.type))
        return 1 if len(links) >= MAX_LINKS else None  # anything but None stops

    def on_object(name: bytes, info: h5o.ObjInfo) -> int | None:
        if info.type == h5o.TYPE_DATASET:
            datasets.append(name)
        return 1 if len(datasets) >= MAX_LINKS else None

    try:
        f.id.links.visit(on_link, info=True)
        h5o.visit(f.id, on_object, info=True)  # objects reached by hard links only
        named = {_external(f, name, kind, what, external) for name, kind in links}
        for name in datasets:
            _check_storage(f, name, what)
    except ArchiveError:
        raise
    except Exception as exc:  # noqa: BLE001 (h5py raises many kinds from a damaged file)
        raise ArchiveError(f"{what} is damaged: {_first_line(exc)}") from None
    if len(links) >= MAX_LINKS or len(datasets) >= MAX_LINKS:
        raise ArchiveError(f"{what} holds more than {MAX_LINKS:,} links; it is not an archive")
    return named


def _external(
    f: h5py.File, name: bytes, kind: int, what: str, allowed: Callable[[str], bool] | None
) -> str:
    """The data file an allowed external link names; ArchiveError for any other link."""
    text = name.decode(errors="replace")
    where = f"{what}: {printable(text, 120)}"
    if kind == h5l.TYPE_SOFT:
        raise ArchiveError(f"{where} is a soft link; an archive holds none, refusing it")
    if kind != h5l.TYPE_EXTERNAL:
        raise ArchiveError(f"{where} is a link of an unknown kind; refusing it")
    filename, path = (x.decode(errors="replace") for x in f.id.links.get_val(name))
    if allowed is None or not allowed(text):
        raise ArchiveError(
            f"{where} is an external link to {printable(filename, 120)!r}; an archive's "
            "files reach no other file, refusing it"
        )
    if path != "/":
        raise ArchiveError(f"{where} links into {printable(path, 60)!r}, not a file's root")
    return data_file_name(filename, where)


def _check_storage(f: h5py.File, name: bytes, what: str) -> None:
    where = f"{what}: {printable(name.decode(errors='replace'), 120)}"
    plist = h5d.open(f.id, name).get_create_plist()
    if plist.get_layout() == h5d.VIRTUAL:
        raise ArchiveError(f"{where} is a virtual dataset (read from other files); refusing it")
    if plist.get_external_count():
        outside = plist.get_external(0)[0].decode(errors="replace")
        raise ArchiveError(
            f"{where} keeps its data in other files ({printable(outside, 80)!r}); refusing it"
        )


@contextlib.contextmanager
def open_hdf5(handle: Opened, what: str) -> Iterator[h5py.File]:
    """The HDF5 file on the open regular file ``handle``, read-only (libhdf5 reads it
    through the descriptor, never by a name)."""
    try:
        signed = is_hdf5(handle)
    except OSError as exc:
        raise ArchiveError(f"{what} cannot be read: {exc.strerror}") from None
    if not signed:
        raise ArchiveError(f"{what} is not an HDF5 file")
    try:
        f = h5py.File(handle, "r")
    except Exception as exc:  # noqa: BLE001 (OSError, RuntimeError, ... from a damaged file)
        raise ArchiveError(f"{what} cannot be opened: {_first_line(exc)}") from None
    with f:
        yield f


def identity(handle: Opened) -> tuple[int, ...]:
    """What identifies an open file's contents: its inode and the times and size of its
    last change (an archive's files are replaced by a rename, never changed in place)."""
    status = os.fstat(handle.fileno())
    return status.st_dev, status.st_ino, status.st_size, status.st_mtime_ns, status.st_ctime_ns


def check_once(
    f: h5py.File,
    handle: Opened,
    what: str,
    checked: dict[tuple[int, ...], set[str]] | None,
    external: Callable[[str], bool] | None = None,
) -> set[str]:
    """:func:`check_contained`, remembered in ``checked`` by the file's identity (a
    command reads one index or data file many times)."""
    key = identity(handle)
    if checked is not None and key in checked:
        return checked[key]
    named = check_contained(f, what, external)
    if checked is not None:
        checked[key] = named
    return named


@contextlib.contextmanager
def data_file(
    data: Path,
    recorded: object,
    what: str,
    checked: dict[tuple[int, ...], set[str]] | None = None,
) -> Iterator[h5py.File]:
    """The data file an index link records (``recorded``, its file name), opened in the
    archive's own data directory ``data`` without following a link, checked to hold
    nothing that reaches other files (once per file in ``checked``)."""
    name = data_file_name(recorded, what)
    with directory(data, f"{what}: the data directory") as fd:
        handle = open_regular(
            name, f"{what}: the data file {data / name}", dir_fd=fd, label=str(data / name)
        )
    with handle, open_hdf5(handle, f"{what}: the data file {data / name}") as f:
        check_once(f, handle, f"{what}: the data file {data / name}", checked)
        yield f


def _first_line(exc: BaseException) -> str:
    text = str(exc).strip().splitlines()
    return printable(text[0], 200) if text else type(exc).__name__
