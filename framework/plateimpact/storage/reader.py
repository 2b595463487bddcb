"""Reading the files of an archive: the index, the data files its links name, datasets
and sealed attributes, every failure one line (storage.archive)."""

from __future__ import annotations

import contextlib
import os
from collections.abc import Iterator, Sequence
from pathlib import Path, PurePath

import h5py
import numpy as np

from ..errors import ArchiveError, PlateImpactError
from ..ragged import Ragged
from .append import FORMAT, FORMAT_VERSION, READABLE_VERSIONS, data_directory
from .hdf5 import SEAL, digest, plain_attributes
from .netcdf import POINT, SAMPLE


class ArchiveFiles:
    """The files of the archive at ``path`` (the index, its data directory and lock),
    and how they are read."""

    def __init__(self, path: str | os.PathLike[str]) -> None:
        self.path = Path(path)
        self.named = bool(os.fspath(path))  # Path("") is Path("."): keep what was given
        self.real = Path(os.path.realpath(path)) if self.named else self.path
        # (a name-less path, "" or "/", is refused by every method before the lock is used)
        self.lock_path = self.real.parent / f"{self.real.name or 'root'}.lock"
        self.data = data_directory(self.real) if self.real.name else self.real

    @contextlib.contextmanager
    def _open(self) -> Iterator[h5py.File]:
        if not self.named:
            raise ArchiveError("give an archive file name, got ''")
        if not self.real.exists():
            raise ArchiveError(f"archive {self.path} does not exist")
        if not self.real.is_file():
            raise ArchiveError(f"archive {self.path} is not a file")
        with self._hdf5(self.real, f"archive {self.path}") as f:
            if f.attrs.get("format") != FORMAT:
                raise ArchiveError(f"{self.path} is an HDF5 file but not a plateimpact archive")
            version = f.attrs.get("format_version")
            if version not in READABLE_VERSIONS:
                raise ArchiveError(
                    f"archive {self.path} has format version {version}; this plateimpact "
                    f"reads versions {', '.join(map(str, READABLE_VERSIONS))} and writes "
                    f"version {FORMAT_VERSION}"
                )
            yield f

    @contextlib.contextmanager
    def _hdf5(self, path: Path, what: str) -> Iterator[h5py.File]:
        """An HDF5 file of the archive, opened for reading; damage is one line."""
        if not os.access(path, os.R_OK):
            raise ArchiveError(f"{what} cannot be read: permission denied")
        try:
            hdf5 = h5py.is_hdf5(path)
        except OSError as exc:
            raise ArchiveError(f"{what} cannot be read: {_first_line(exc)}") from None
        if not hdf5:
            raise ArchiveError(f"{path} is not an HDF5 file")
        try:
            f = h5py.File(path, "r")
        except OSError as exc:
            raise ArchiveError(f"{what} cannot be opened: {_first_line(exc)}") from None
        with f:
            try:
                yield f
            except PlateImpactError:
                raise
            except (OSError, RuntimeError, KeyError, ValueError, TypeError) as exc:
                # Damaged structure (not just damaged data, which the checksums catch):
                # h5py raises any of these from a corrupt header, link or attribute.
                raise ArchiveError(f"{what} is damaged: {_first_line(exc)}") from None

    @contextlib.contextmanager
    def _linked(self, f: h5py.File, path: str) -> Iterator[h5py.Group]:
        """The group at ``path`` of the index ``f``: in format 2 the root of the data file
        its link names (opened here, relative to the index, whatever the working
        directory), in format 1 the group itself."""
        link = f.get(path, getlink=True)
        if not isinstance(link, h5py.ExternalLink):
            yield f[path]
            return
        # Our own data directory, by the index's name now (renamed with the index, an
        # archive still reads; h5py's own link following needs the names it was made with).
        target = self.data / PurePath(link.filename).name
        if not target.is_file():
            raise ArchiveError(
                f"archive {self.path}: the data file of {path} ({target}) is missing"
            )
        with self._hdf5(target, f"archive {self.path}: data file {target}") as data:
            yield data[link.path]

    def _read(self, group: h5py.Group, path: str) -> np.ndarray:
        try:
            return np.asarray(group[path][()])
        except (OSError, KeyError, ValueError, MemoryError) as exc:  # memory: a damaged shape
            raise ArchiveError(
                f"archive {self.path}: {group.file.filename}:{group.name.rstrip('/')}/{path} "
                f"cannot be read ({_first_line(exc)}); the file is damaged"
            ) from None

    def _read_ragged(
        self, group: h5py.Group, prefix: str, counts: str, per_row: Sequence[str],
        first: Sequence[str],
    ) -> Ragged:  # fmt: skip
        """A ragged array stored as ``PREFIX<column>`` (format 1: a subgroup, ``prefix``
        ``"trajectory/"``), its columns in the order ``first`` names them, then the rest."""
        if prefix.endswith("/"):
            stored = [k for k in group[prefix.rstrip("/")] if k != counts]
        else:
            dimensions = (SAMPLE, POINT)  # netCDF's datasets of its dimensions
            stored = [k.removeprefix(prefix) for k in group if k.startswith(prefix)]
            stored = [k for k in stored if prefix + k not in dimensions]
            stored = [k for k in stored if k != counts]
        names = [k for k in first if k in stored] + [k for k in stored if k not in first]
        values = {k: self._read(group, prefix + k) for k in names if k not in per_row}
        rows = {k: self._read(group, prefix + k) for k in names if k in per_row}
        try:
            return Ragged(self._read(group, prefix + counts), values, rows)
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


def _first_line(exc: BaseException) -> str:
    text = str(exc).strip().splitlines()
    return text[0] if text else type(exc).__name__
