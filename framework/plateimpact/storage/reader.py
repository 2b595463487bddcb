"""Reading the files of an archive: the index, the data files its links name, datasets
and sealed attributes, every failure one line (storage.archive)."""

from __future__ import annotations

import contextlib
import errno
import os
from collections.abc import Iterator, Sequence
from pathlib import Path

import h5py
import numpy as np

from ..base.errors import ArchiveError, PlateImpactError
from ..base.untrusted import printable
from ..model.ragged import Ragged
from .append import FORMAT, FORMAT_VERSION, READABLE_VERSIONS
from .confined import SLACK, Opened, check_lengths, open_regular, shown_version
from .contained import check_once, data_file, index_link_allowed, open_hdf5
from .data_files import data_directory
from .hdf5 import SEAL, digest, plain_attributes
from .netcdf import POINT, SAMPLE


class ArchiveFiles:
    """The files of the archive at ``path`` (the index, its data directory and lock),
    and how they are read: each opened by descriptor as a regular file (the data files
    in the archive's own data directory, never through a link) and checked to reach no
    other file (storage.contained) before anything in it is read."""

    def __init__(self, path: str | os.PathLike[str]) -> None:
        self.path = Path(path)
        self.named = bool(os.fspath(path))  # Path("") is Path("."): keep what was given
        self.real = Path(os.path.realpath(path)) if self.named else self.path
        # (a name-less path, "" or "/", is refused by every method before the lock is used)
        self.lock_path = self.real.parent / f"{self.real.name or 'root'}.lock"
        self.data = data_directory(self.real) if self.real.name else self.real
        self._checked: dict[tuple[int, ...], set[str]] = {}  # files found contained
        self._sizes: dict[str, int] = {}  # scenes per study, by its scenes' data file

    def _exists(self) -> bool:
        """Whether the index is there (a path too long to look at is an ArchiveError)."""
        try:
            os.stat(self.real)
        except FileNotFoundError:
            return False
        except OSError as exc:
            if exc.errno == errno.ENAMETOOLONG:
                check_lengths(self.path, self.real, f"archive {printable(self.path, 80)}")
            raise ArchiveError(f"archive {self.path} cannot be examined: {exc.strerror}") from None
        return True

    @contextlib.contextmanager
    def _open(self) -> Iterator[h5py.File]:
        if not self.named:
            raise ArchiveError("give an archive file name, got ''")
        if not self._exists():
            raise ArchiveError(f"archive {self.path} does not exist")
        if self.real.is_dir():
            raise ArchiveError(f"archive {self.path} is not a file")
        what = f"archive {self.path}"
        handle = open_regular(self.real, what, follow=True, label=str(self.path))
        with self._hdf5(handle, what) as f:
            if f.attrs.get("format") != FORMAT:
                raise ArchiveError(f"{self.path} is an HDF5 file but not a plateimpact archive")
            version = f.attrs.get("format_version")
            if version not in READABLE_VERSIONS:
                raise ArchiveError(
                    f"archive {self.path} has format version {shown_version(version)}; this "
                    f"plateimpact reads versions {', '.join(map(str, READABLE_VERSIONS))} and "
                    f"writes version {FORMAT_VERSION}"
                )
            links = index_link_allowed if version == FORMAT_VERSION else None
            check_once(f, handle, what, self._checked, links)
            yield f

    @contextlib.contextmanager
    def _hdf5(self, handle: Opened, what: str) -> Iterator[h5py.File]:
        """The HDF5 file open on ``handle``, read-only; damage is one line."""
        with handle, open_hdf5(handle, what) as f:
            try:
                yield f
            except PlateImpactError:
                raise
            except (OSError, RuntimeError, KeyError, ValueError, TypeError, AttributeError) as exc:
                # Damaged structure (not just damaged data, which the checksums catch):
                # h5py raises any of these from a corrupt header, link or attribute, and
                # an index from someone else may hold a dataset where a group belongs.
                raise ArchiveError(f"{what} is damaged: {_first_line(exc)}") from None

    @contextlib.contextmanager
    def _linked(self, f: h5py.File, path: str) -> Iterator[h5py.Group]:
        """The group at ``path`` of the index ``f``: in format 2 the root of the data file
        its link names (by its file name in the archive's data directory now, whatever
        directory the link recorded: a renamed archive still reads, and nothing outside
        is reached), in format 1 the group itself."""
        link = f.get(path, getlink=True)
        if link is None:
            raise ArchiveError(
                f"archive {self.path}: {printable(path)} is missing; the archive is damaged"
            )
        if not isinstance(link, h5py.ExternalLink):
            found = f[path]
            if not isinstance(found, h5py.Group):
                raise ArchiveError(
                    f"archive {self.path}: {printable(path)} is not a group; the archive is damaged"
                )
            yield found
            return
        what = f"archive {self.path}: {printable(path)}"
        with data_file(self.data, link.filename, what, self._checked) as data:
            try:
                yield data
            except PlateImpactError:
                raise
            except (OSError, RuntimeError, KeyError, ValueError, TypeError, AttributeError) as exc:
                raise ArchiveError(f"{what} is damaged: {_first_line(exc)}") from None

    def _study_size(self, f: h5py.File, study: str) -> int:
        """How many scenes ``study`` has (remembered by its scenes' data file, which is
        written once and never changed)."""
        link = f.get(f"{study}/scenes", getlink=True)
        key = link.filename if isinstance(link, h5py.ExternalLink) else None
        if key is None or key not in self._sizes:
            with self._linked(f, f"{study}/scenes") as scenes:
                size = self._scene_count(scenes)
            if key is None:
                return size
            self._sizes[key] = size
        return self._sizes[key]

    def _scene_count(self, scenes: h5py.Group) -> int:
        """How many scenes the study's scenes group or file holds (its first column's
        length, read without reading the column)."""
        first = scenes.get("impact_speed")
        if not isinstance(first, h5py.Dataset) or first.ndim != 1:
            raise ArchiveError(
                f"archive {self.path}: {scenes.file.filename}:{scenes.name} holds no scenes; "
                "the file is damaged"
            )
        return int(first.shape[0])

    def _read(
        self, group: h5py.Group, path: str, kinds: str = "", shape: tuple[int, ...] | None = None
    ) -> np.ndarray:
        """The dataset at ``path`` of ``group``: a dataset (of one of the dtype ``kinds``,
        and of ``shape``, if given), no larger than its file could hold, read whole."""

        def where() -> str:
            name = printable(f"{group.name.rstrip('/')}/{path}", 120)
            return f"archive {self.path}: {group.file.filename}:{name}"

        try:
            dataset = group.get(path)
            if not isinstance(dataset, h5py.Dataset):
                raise ArchiveError(f"{where()} is missing or not a dataset; the file is damaged")
            if kinds and dataset.dtype.kind not in kinds:
                expected = "text" if kinds == "O" else "numbers"
                raise ArchiveError(
                    f"{where()} holds {printable(dataset.dtype, 40)} where {expected} belong; "
                    "the file is damaged"
                )
            if shape is not None and dataset.shape != shape:
                raise ArchiveError(
                    f"{where()} has shape {dataset.shape}, not {shape}; the file is damaged"
                )
            if dataset.nbytes > _file_size(dataset) + SLACK:
                raise ArchiveError(
                    f"{where()} declares {dataset.nbytes:,} bytes, more than its file holds; "
                    "the file is damaged"
                )
            return np.asarray(dataset[()])
        except (OSError, KeyError, ValueError, TypeError, MemoryError) as exc:  # memory: a shape
            if isinstance(exc, PlateImpactError):
                raise
            raise ArchiveError(
                f"{where()} cannot be read ({_first_line(exc)}); the file is damaged"
            ) from None

    def _read_ragged(
        self, group: h5py.Group, prefix: str, counts: str, per_row: Sequence[str],
        first: Sequence[str], size: int,
    ) -> Ragged:  # fmt: skip
        """A ragged array of ``size`` rows stored as ``PREFIX<column>`` (format 1: a
        subgroup, ``prefix`` ``"trajectory/"``), its columns in the order ``first`` names
        them, then the rest; every column checked against the counts before use."""
        if prefix.endswith("/"):
            stored = [k for k in group[prefix.rstrip("/")] if k != counts]
        else:
            dimensions = (SAMPLE, POINT)  # netCDF's datasets of its dimensions
            stored = [k.removeprefix(prefix) for k in group if k.startswith(prefix)]
            stored = [k for k in stored if prefix + k not in dimensions]
            stored = [k for k in stored if k != counts]
        names = [k for k in first if k in stored] + [k for k in stored if k not in first]
        row_counts = self._read(group, prefix + counts, "iu", (size,))
        if size and row_counts.min() < 0:
            raise ArchiveError(f"archive {self.path}: {prefix} has a negative count; it is damaged")
        total = int(row_counts.sum())
        values = {
            k: self._read(group, prefix + k, "f", (total,)) for k in names if k not in per_row
        }
        rows = {k: self._read(group, prefix + k, "f", (size,)) for k in names if k in per_row}
        try:
            return Ragged(row_counts, values, rows)
        except ValueError as exc:
            raise ArchiveError(f"archive {self.path}: {prefix} is damaged ({exc})") from None

    def _check_seal(self, group: h5py.Group) -> dict[str, object]:
        """The group's attributes, after checking them against their digest (attributes
        have no fletcher32 checksum of their own)."""
        attributes = plain_attributes(group)
        sealed = attributes.pop(SEAL, None)
        where = f"{group.file.filename}:{group.name}" if group.name == "/" else group.name
        if sealed is None:
            raise ArchiveError(
                f"archive {self.path}: the attributes of {where} are damaged "
                "(their digest is missing)"
            )
        if sealed != digest(attributes):
            raise ArchiveError(
                f"archive {self.path}: the attributes of {where} are damaged "
                "(their digest does not match)"
            )
        return attributes


def _file_size(dataset: h5py.Dataset) -> int:
    """The size of the file holding ``dataset`` [bytes] (HDF5's end-of-file address)."""
    return int(h5py.h5i.get_file_id(dataset.id).get_filesize())


def _first_line(exc: BaseException) -> str:
    text = str(exc).strip().splitlines()
    return printable(text[0], 200) if text else type(exc).__name__
