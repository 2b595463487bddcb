"""The files of an archive, opened and written so that nothing reaches outside them.

An archive may come from someone else (a tarball of ``a.h5``, ``a.h5.d/`` and
``a.h5.lock``), so every name in it is untrusted. The rules (docs/archive.md, "Files from
someone else"):

* The index the user named may be a symlink (followed by design, as any output is);
  nothing inside the archive's own files is: its data directory and lock are opened
  with ``O_NOFOLLOW``, and every data file relative to the data directory's descriptor
  (``openat``), so no symlink at any level leads out, and swapping the directory after
  it was opened changes nothing.
* Only regular files are opened, and checked to be so with ``fstat`` on the open
  descriptor (``O_NONBLOCK``, so a FIFO never hangs the open).
* A data file's recorded name must be one this plateimpact writes
  (:data:`DATA_NAME`); only its base name is used, in the archive's current data
  directory.
* Cleanup deletes only what it can prove a writer made: names that parse exactly as a
  data file or a temporary of *this* archive, regular files with one link, and a
  temporary only when the process that made it is gone.
* Files are written whole from memory (libhdf5 never writes to a disk): a temporary
  beside the target (``O_EXCL | O_NOFOLLOW``), fsync'ed, renamed over the target.
"""

from __future__ import annotations

import contextlib
import errno
import io
import os
import re
import secrets
import stat
from collections.abc import Callable, Iterator
from pathlib import Path
from typing import BinaryIO

import numpy as np

from ..base.errors import ArchiveError
from ..base.untrusted import printable
from .output import TEMPORARY_EXTRA, pid_alive, temporary_owner, umask

#: A data file's name: ``SLUG.XXXXXXXX.nc`` (the slug of study and run, at most 60
#: characters; 8 random hexadecimal digits).
DATA_NAME = re.compile(r"[A-Za-z0-9._+-]{1,60}\.[0-9a-f]{8}\.nc")
#: The longest data file name [bytes].
LONGEST_DATA_NAME = 60 + 12
#: The HDF5 signature, at 0, 512, 1024, 2048, ... bytes (after a user block).
SIGNATURE = b"\x89HDF\r\n\x1a\n"
#: How much a dataset may declare beyond the bytes of its file [bytes]: a dataset we
#: wrote holds its data (no compression), so a larger one is a damaged or hostile shape.
SLACK = 1 << 20

READ_FLAGS = os.O_RDONLY | os.O_NOFOLLOW | os.O_NONBLOCK | os.O_CLOEXEC
DIRECTORY_FLAGS = os.O_RDONLY | os.O_DIRECTORY | os.O_NOFOLLOW | os.O_CLOEXEC


def data_file_name(recorded: object, what: str) -> str:
    """The base name of the data file an index link records (``DIR.d/NAME``), after
    checking it is one this plateimpact writes: ``DIR.d`` a plain directory name (the
    archive's, perhaps under an earlier name: only the base name is used, in the
    archive's current data directory), ``NAME`` of :data:`DATA_NAME`. Anything else
    (absolute, ``..``, another depth, another pattern) is an ArchiveError."""
    text = recorded.decode(errors="replace") if isinstance(recorded, bytes) else str(recorded)
    folder, slash, name = text.partition("/")
    plain = bool(slash) and folder.endswith(".d") and folder not in ("", ".", "..")
    if not (plain and folder.isprintable() and DATA_NAME.fullmatch(name)):
        raise ArchiveError(
            f"{what} names the data file {printable(text, 120)!r}, not a file of its own data "
            "directory; the archive is damaged or was made to reach outside itself"
        )
    return name


def shown_version(version: object) -> str:
    """A format version read from a file, for a message: an integer as it is, anything
    else as its (inert, short) repr."""
    if isinstance(version, int | np.integer) and not isinstance(version, bool):
        return str(int(version))
    return printable(repr(version), 40)


def _pathconf(directory: Path, name: str, default: int) -> int:
    try:
        return os.pathconf(directory, name)
    except (OSError, ValueError):
        return default


def check_lengths(given: str | os.PathLike[str], real: Path, what: str, extra: int = 0) -> None:
    """Refuse, before any work, an archive some of whose files could not be made: the
    index's temporaries (``.NAME.PID.XXXXXXXX.tmp``; ``extra`` more bytes for names
    longer than the index's) must fit NAME_MAX, and the deepest path (a data file's
    temporary in ``NAME.d``) PATH_MAX."""
    path_max = _pathconf(real.parent, "PC_PATH_MAX", 4096) if os.path.isdir(real.parent) else 4096
    for path in (os.fsencode(given), os.fsencode(real)):
        below = len(".d/") + LONGEST_DATA_NAME + TEMPORARY_EXTRA  # its deepest file
        if len(path) + below >= path_max:
            raise ArchiveError(
                f"{what}: the path is {len(path):,} bytes; with the files it holds it must be "
                f"at most {path_max - 1 - below:,} (PATH_MAX {path_max})"
            )
    name_max = _pathconf(real.parent, "PC_NAME_MAX", 255) if os.path.isdir(real.parent) else 255
    name = len(os.fsencode(real.name))
    if name + TEMPORARY_EXTRA + extra > name_max:
        raise ArchiveError(
            f"{what}: the file name is {name} bytes; with its temporaries it must be at most "
            f"{name_max - TEMPORARY_EXTRA - extra} (NAME_MAX {name_max})"
        )


def _reason(exc: OSError) -> str:
    if exc.errno == errno.EACCES:
        return "permission denied"
    return exc.strerror or os.strerror(exc.errno or errno.EIO)


def open_directory(path: Path, what: str, dir_fd: int | None = None, follow: bool = False) -> int:
    """A descriptor of the directory ``path`` (its last name relative to ``dir_fd`` if
    given), which must not be a symlink unless ``follow`` (a directory the user named)."""
    name = path.name if dir_fd is not None else path
    flags = DIRECTORY_FLAGS & ~os.O_NOFOLLOW if follow else DIRECTORY_FLAGS
    try:
        return os.open(name, flags, dir_fd=dir_fd)
    except OSError as exc:
        if exc.errno in (errno.ELOOP, errno.ENOTDIR) and _is_link(name, dir_fd):
            raise ArchiveError(
                f"{what} {path} is a symbolic link; an archive's data directory must be a "
                "directory of its own (copy the files into one)"
            ) from None
        if exc.errno == errno.ENOTDIR:
            raise ArchiveError(f"{what} {path} is not a directory") from None
        if exc.errno == errno.ENOENT:
            raise ArchiveError(f"{what} {path} is missing") from None
        raise ArchiveError(f"{what} {path} cannot be opened: {_reason(exc)}") from None


def _is_link(name: str | Path, dir_fd: int | None) -> bool:
    try:
        return stat.S_ISLNK(os.stat(name, dir_fd=dir_fd, follow_symlinks=False).st_mode)
    except OSError:
        return False


@contextlib.contextmanager
def directory(
    path: Path, what: str, dir_fd: int | None = None, follow: bool = False
) -> Iterator[int]:
    """:func:`open_directory`, closed on leaving."""
    fd = open_directory(path, what, dir_fd, follow)
    try:
        yield fd
    finally:
        os.close(fd)


def data_temporary(name: str) -> bool | None:
    """Whether ``name`` is the temporary of a data file (``.DATA.PID.XXXXXXXX.tmp``,
    or ``.DATA.XXXXXXXX.tmp`` from ``tempfile`` as earlier versions wrote) whose writer
    is gone (True), one whose writer lives (False), or not one at all (None)."""
    if not (name.startswith(".") and name.endswith(".tmp")):
        return None
    rest = name[1:-4]
    three = rest.rsplit(".", 2)
    if len(three) == 3 and DATA_NAME.fullmatch(three[0]) and three[1].isdigit():
        if re.fullmatch(r"[0-9a-f]{8}", three[2]) and len(three[1]) <= 10:
            return not pid_alive(int(three[1]))
    two = rest.rsplit(".", 1)
    if len(two) == 2 and DATA_NAME.fullmatch(two[0]) and re.fullmatch(r"[a-z0-9_]{8}", two[1]):
        return True  # earlier versions wrote these only holding the lock, which we hold
    return None


def open_regular(
    name: str | Path,
    what: str,
    dir_fd: int | None = None,
    follow: bool = False,
    label: str = "",
) -> Opened:
    """``name`` (relative to ``dir_fd`` if given; shown as ``label``) opened for reading,
    after checking on the open descriptor that it is a regular file; a symlink is
    refused unless ``follow`` (the index the user named)."""
    flags = READ_FLAGS & ~os.O_NOFOLLOW if follow else READ_FLAGS
    try:
        fd = os.open(name, flags, dir_fd=dir_fd)
    except OSError as exc:
        if exc.errno == errno.ELOOP:
            raise ArchiveError(f"{what} is a symbolic link; refusing to follow it") from None
        if exc.errno == errno.ENOENT:
            raise ArchiveError(f"{what} is missing") from None
        raise ArchiveError(f"{what} cannot be read: {_reason(exc)}") from None
    try:
        if not stat.S_ISREG(os.fstat(fd).st_mode):
            raise ArchiveError(f"{what} is not a regular file")
        os.set_blocking(fd, True)
        return Opened(fd, label or os.fspath(name))
    except BaseException:
        os.close(fd)
        raise


class Opened(io.FileIO):
    """A file opened by descriptor that shows as its path (h5py names a file object by
    its ``repr``: ``h5py.File(handle).filename`` is then the path, for messages)."""

    def __init__(self, fd: int, label: str) -> None:
        super().__init__(fd, "rb", closefd=True)
        self.label = label

    def __repr__(self) -> str:
        return self.label


def is_hdf5(handle: BinaryIO) -> bool:
    """Whether the open file holds the HDF5 signature where HDF5 looks for it."""
    fd = handle.fileno()
    size = os.fstat(fd).st_size
    offset = 0
    while offset + len(SIGNATURE) <= size:
        if os.pread(fd, len(SIGNATURE), offset) == SIGNATURE:
            return True
        offset = 512 if offset == 0 else offset * 2
    return False


def temporary_name(target: str) -> str:
    """A fresh temporary's name for ``target``: ``.TARGET.PID.XXXXXXXX.tmp``."""
    return f".{target}.{os.getpid()}.{secrets.token_hex(4)}.tmp"


def removable(dir_fd: int, name: str) -> bool:
    """Whether ``name`` in ``dir_fd`` is a regular file with one link (never a symlink,
    a directory, a device or a second name of someone's file)."""
    try:
        status = os.stat(name, dir_fd=dir_fd, follow_symlinks=False)
    except OSError:
        return False
    return stat.S_ISREG(status.st_mode) and status.st_nlink == 1


def remove_dead_temporaries(dir_fd: int, target: str, names: list[str] | None = None) -> None:
    """Delete the temporaries of ``target`` in ``dir_fd`` whose writer is gone."""
    for name in os.listdir(dir_fd) if names is None else names:
        owner = temporary_owner(name, target)
        if owner is not None and not pid_alive(owner) and removable(dir_fd, name):
            with contextlib.suppress(FileNotFoundError):
                os.unlink(name, dir_fd=dir_fd)


def give_mode(fd: int, like: Path | None) -> None:
    """The mode, owner and group of ``like`` (as far as this process may), else the mode
    a new file gets under the umask."""
    try:
        status = os.stat(like) if like is not None else None
    except FileNotFoundError:
        status = None
    if status is None:
        os.fchmod(fd, 0o666 & ~umask())
        return
    os.fchmod(fd, stat.S_IMODE(status.st_mode))
    try:
        os.fchown(fd, status.st_uid, status.st_gid)
    except PermissionError:  # not ours to give away: keep the group if we may
        with contextlib.suppress(PermissionError):
            os.fchown(fd, -1, status.st_gid)


def write_file(
    dir_fd: int,
    name: str,
    data: bytes | memoryview,
    like: Path | None,
    fault: Callable[[str], None] = lambda stage: None,
) -> None:
    """Write ``data`` as ``name`` in ``dir_fd`` atomically: a temporary beside it
    (created exclusively, never through a link), written, fsync'ed, given ``like``'s
    mode, renamed over ``name``; ``fault(stage)`` at "fsync" and "replace". On any
    failure the temporary is removed and ``name`` is as it was."""
    temporary = temporary_name(name)
    flags = os.O_WRONLY | os.O_CREAT | os.O_EXCL | os.O_NOFOLLOW | os.O_CLOEXEC
    fd = os.open(temporary, flags, 0o600, dir_fd=dir_fd)
    try:
        try:
            view = memoryview(data)
            while view:
                view = view[os.write(fd, view) :]
            fault("fsync")
            os.fsync(fd)
            give_mode(fd, like)
        finally:
            os.close(fd)
        fault("replace")
        os.replace(temporary, name, src_dir_fd=dir_fd, dst_dir_fd=dir_fd)
    except BaseException:
        with contextlib.suppress(OSError):
            os.unlink(temporary, dir_fd=dir_fd)
        raise


def fsync_fd(fd: int) -> None:
    """Make the renames in the directory ``fd`` durable."""
    with contextlib.suppress(OSError):
        os.fsync(fd)
