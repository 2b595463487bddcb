"""The data files of a format-2 archive (``ARCHIVE.d/*.nc``) as one append writes them:
in memory first, then each atomically into the archive's own data directory (never a
symlink), and what killed writers left behind removed, provably theirs only."""

from __future__ import annotations

import contextlib
import io
import os
import re
import secrets
from collections.abc import Callable
from pathlib import Path
from typing import BinaryIO

from ..base.errors import ArchiveError
from .confined import (
    DATA_NAME,
    data_file_name,
    data_temporary,
    fsync_fd,
    open_directory,
    open_regular,
    removable,
    remove_dead_temporaries,
    write_file,
)

#: The largest index read [bytes]: an index holds names and links only (67 KiB for 200
#: runs), so a larger file is not one.
MAX_INDEX_BYTES = 256 << 20


def data_directory(real: Path) -> Path:
    """Where the data files of the archive (index) ``real`` live: ``ARCHIVE.d``."""
    return real.with_name(f"{real.name}.d")


def _slug(text: str) -> str:
    return re.sub(r"[^A-Za-z0-9._+-]+", "_", text)[:60] or "_"


def encoded(write: Callable[[BinaryIO], object]) -> bytes:
    """The bytes of a file made by ``write(handle)`` in memory (libhdf5 writes to no
    disk, so a full disk is a plain OSError of the writer that puts the bytes there)."""
    buffer = io.BytesIO()
    write(buffer)
    return buffer.getvalue()


class DataFiles:
    """The data files one append writes, in the archive's own data directory (made if
    new; never a symlink): each complete and fsync'ed before the index names it; removed
    again if the append fails; files it retires (a run replaced by ``overwrite``)
    removed only once the new index is in place, and only if it names them no more."""

    def __init__(self, real: Path, parent: int) -> None:
        self.real = real
        self.parent = parent
        self.directory = data_directory(real)
        self.written: list[str] = []
        self.retired: list[str] = []
        self.kept: set[str] = set()  # the data files the new index names, if retiring
        self._fd: int | None = None

    def existing(self) -> int | None:
        """The data directory's descriptor; None if there is none yet."""
        if self._fd is None:
            try:
                os.stat(self.directory.name, dir_fd=self.parent, follow_symlinks=False)
            except FileNotFoundError:
                return None
            self._fd = open_directory(
                self.directory, f"archive {self.real}: its data directory", self.parent
            )
        return self._fd

    def fd(self) -> int:
        """The data directory's descriptor, the directory made if new (readable by whoever
        may read the index)."""
        if self.existing() is None:
            with contextlib.suppress(FileExistsError):
                os.mkdir(self.directory.name, 0o777, dir_fd=self.parent)
            fd = self.existing()
            assert fd is not None
            with contextlib.suppress(FileNotFoundError):
                readers = os.stat(self.real).st_mode & 0o044
                os.fchmod(fd, 0o700 | readers | readers >> 2)
        assert self._fd is not None
        return self._fd

    def new(self, stem: str, write: Callable[[BinaryIO], object]) -> str:
        """Write a data file through ``write(handle)`` (in memory, then atomically to the
        data directory); returns its name relative to the index's directory (the external
        link's target, with the data directory's current name)."""
        data = encoded(write)
        name = self._fresh(stem)
        write_file(self.fd(), name, data, self.real)
        self.written.append(name)
        return f"{self.directory.name}/{name}"

    def _fresh(self, stem: str) -> str:
        """A data file name no file in the data directory has (the rename that puts the
        file there would replace one; we hold the lock, so none appears meanwhile)."""
        while True:
            name = f"{_slug(stem)}.{secrets.token_hex(4)}.nc"
            try:
                os.stat(name, dir_fd=self.fd(), follow_symlinks=False)
            except FileNotFoundError:
                return name

    def retire(self, target: str) -> None:
        self.retired.append(data_file_name(target, f"archive {self.real}"))

    def sync(self) -> None:
        if self.written:
            fsync_fd(self.fd())

    def rollback(self) -> None:
        for name in self.written:
            with contextlib.suppress(OSError):
                os.unlink(name, dir_fd=self.fd())

    def commit(self) -> None:
        for name in self.retired:
            if name not in self.kept:
                with contextlib.suppress(OSError):
                    os.unlink(name, dir_fd=self.fd())

    def close(self) -> None:
        if self._fd is not None:
            os.close(self._fd)
            self._fd = None


def remove_orphans(files: DataFiles, named: set[str]) -> None:
    """Remove what killed writers left: their temporaries beside the index and in its
    data directory, and data files the index does not name (``named``). Only names that
    parse exactly as this archive's own, regular files with one link, and temporaries
    whose writer is gone. The caller holds the lock."""
    remove_dead_temporaries(files.parent, files.real.name)
    fd = files.existing()
    if fd is None:
        return
    for name in os.listdir(fd):
        if DATA_NAME.fullmatch(name):
            orphan = name not in named
        else:
            orphan = bool(data_temporary(name))
        if orphan and removable(fd, name):
            with contextlib.suppress(FileNotFoundError):
                os.unlink(name, dir_fd=fd)


def read_index(parent: int, real: Path) -> bytes | None:
    """The bytes of the index ``real`` (None if there is none yet), read through the
    descriptor of its directory, without following a link swapped in since."""
    try:
        os.stat(real.name, dir_fd=parent, follow_symlinks=False)
    except FileNotFoundError:
        return None
    with open_regular(real.name, f"archive {real}", dir_fd=parent) as handle:
        size = os.fstat(handle.fileno()).st_size
        if size > MAX_INDEX_BYTES:
            raise ArchiveError(
                f"archive {real}: its index is {size:,} bytes; an index holds names only "
                f"(at most {MAX_INDEX_BYTES:,} are read), so it is not one"
            )
        return handle.read()
