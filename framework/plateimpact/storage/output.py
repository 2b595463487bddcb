"""Every output file plateimpact writes goes through here: checked before any work, then
written atomically, so that nothing is ever half-written, replaced or loosened.

:func:`check_output` refuses, with one line naming the flag, what could not end well:
an empty name, a directory, a name too long, a missing or unwritable directory, a target
that is not a regular file (a device, a fifo, a directory behind a link), a read-only
target, a figure format matplotlib cannot write. :func:`write_output` then writes to a
unique temporary file beside the real target (a symlink is followed: its target is
written), flushes and fsyncs it, gives it the target's mode and group (or the umask's
mode for a new file), and renames it over the target. A failure at any stage (a full
disk, a lost mount) leaves the old file as it was and no temporary file behind.
"""

from __future__ import annotations

import contextlib
import errno
import glob
import hashlib
import os
import re
import stat
import tempfile
from collections.abc import Callable, Iterable
from pathlib import Path
from typing import IO

from ..base.errors import PlateImpactError
from ..base.untrusted import printable

#: What ``kind`` may end with; ``None``: any name.
SUFFIXES: dict[str, tuple[str, ...] | None] = {
    "csv": None,
    "json": None,
    "figure": (".png", ".svg", ".pdf", ".eps", ".ps", ".jpg", ".jpeg", ".tif", ".tiff", ".webp"),
}

#: Resolution of saved raster figures by default, and the range ``--dpi`` accepts [dots
#: per inch]: at 50 a study figure (7.2 in) is a 360-pixel thumbnail; 1200
#: meets any journal's line-art rule, and there ``reproduce``'s figures are 34-72
#: megapixels each (0.8 GB at the peak). Print wants SVG or PDF anyway.
FIGURE_DPI = 150.0
#: What a temporary's name adds to its target's: ``.`` and ``.PID.XXXXXXXX.tmp``, the PID
#: up to 7 digits (Linux's largest pid_max, 2**22) [bytes].
TEMPORARY_EXTRA = 1 + 1 + 7 + 1 + 8 + 4
FIGURE_DPI_RANGE = (50.0, 1200.0)


class OutputError(PlateImpactError, OSError):
    """An output file cannot be written where it was asked for; one line naming the flag."""


def fault_point(stage: str) -> None:
    """Called at each stage of a write ("open", "write", "fsync", "chmod", "replace"; and
    "chunk" before each chunk of a streamed file): nothing, unless a test replaces it to
    fail or crash there deterministically."""


def _name_max(directory: str) -> int:
    try:
        return os.pathconf(directory, "PC_NAME_MAX")
    except (OSError, ValueError):
        return 255


def umask() -> int:
    """The process's umask, read without changing it (Linux), else by setting it back."""
    with contextlib.suppress(OSError, ValueError):
        with open("/proc/self/status") as status:
            for line in status:
                if line.startswith("Umask:"):
                    return int(line.split()[1], 8)
    current = os.umask(0o022)
    os.umask(current)
    return current


def path_max(directory: str | os.PathLike[str]) -> int:
    """The longest path the system takes in ``directory`` [bytes, with its NUL]."""
    try:
        return os.pathconf(directory, "PC_PATH_MAX")
    except (OSError, ValueError):
        return 4096


def unwritable(directory: str | os.PathLike[str]) -> str:
    """Why a directory is not writable: a read-only filesystem, or its permissions."""
    with contextlib.suppress(OSError):
        if os.statvfs(directory).f_flag & os.ST_RDONLY:
            return "not writable (a read-only filesystem)"
    return "not writable"


def shown_path(text: str, limit: int = 200) -> str:
    """A path for a one-line message: quoted, escaped, cut to ``limit`` characters."""
    return printable(repr(text), limit)


def check_path(real: Path, flag: str, spare: int = 0) -> None:
    """Refuse a path the filesystem could not take: longer than PATH_MAX (less ``spare``
    bytes kept for names inside it), a name in it longer than NAME_MAX, or a name in it
    that is a file where a directory must be."""
    longest = path_max("/") - 1 - spare
    size = len(os.fsencode(real))
    if size > longest:
        room = f", {spare} kept for the files inside" if spare else ""
        raise OutputError(
            f"{flag}: the path is {size:,} bytes; at most {longest:,} are written (PATH_MAX "
            f"{path_max('/')}{room})"
        )
    ancestor = real
    while not os.path.lexists(ancestor) and ancestor != ancestor.parent:
        ancestor = ancestor.parent
    for part in real.relative_to(ancestor).parts if ancestor != real else ():
        most = _name_max(str(ancestor) if os.path.isdir(ancestor) else "/")
        if len(os.fsencode(part)) > most:
            raise OutputError(
                f"{flag}: the name {shown_path(part, 60)} is longer than {most} bytes"
            )
    if real != ancestor and not os.path.isdir(ancestor):
        raise OutputError(f"{flag}: {shown_path(str(ancestor))} is not a directory")


def check_output(path: str | os.PathLike[str], flag: str, kind: str = "csv") -> Path:
    """The real file ``path`` names (links followed), after refusing what cannot be
    written there. Call it before any computation."""
    text = os.fspath(path)
    if not text.strip():
        raise OutputError(f"{flag}: give a file name, got {text!r}")
    if "\0" in text:
        raise OutputError(f"{flag}: a file name cannot hold a NUL character")
    longest = path_max("/") - 1 - TEMPORARY_EXTRA  # with its NUL, and its temporary's name
    if len(os.fsencode(text)) > longest:
        raise OutputError(
            f"{flag}: the path is {len(os.fsencode(text)):,} bytes; at most {longest:,} are "
            f"written (PATH_MAX {path_max('/')})"
        )
    real = Path(os.path.realpath(text))
    if len(os.fsencode(real)) > longest:
        raise OutputError(
            f"{flag}: the path leads to {len(os.fsencode(real)):,} bytes; at most {longest:,} "
            f"are written (PATH_MAX {path_max('/')})"
        )
    directory = str(real.parent)
    check_path(real, flag, TEMPORARY_EXTRA)
    if os.path.isdir(directory) and len(real.name.encode()) > _name_max(directory):
        raise OutputError(f"{flag}: the file name is longer than {_name_max(directory)} bytes")
    if text.endswith(os.sep) or real.is_dir():
        raise OutputError(f"{flag}: {shown_path(text)} is a directory; give a file name")
    if not os.path.isdir(directory):
        raise OutputError(f"{flag}: directory {shown_path(directory)} does not exist")
    if not os.access(directory, os.W_OK | os.X_OK):
        raise OutputError(f"{flag}: directory {shown_path(directory)} is {unwritable(directory)}")
    if real.exists() or real.is_symlink():
        try:
            mode = os.stat(real).st_mode
        except OSError as exc:
            raise OutputError(
                f"{flag}: {shown_path(text)} cannot be examined: {exc.strerror}"
            ) from None
        if not stat.S_ISREG(mode):
            raise OutputError(
                f"{flag}: {shown_path(text)} is not a regular file; refusing to replace it"
            )
        if not mode & (stat.S_IWUSR | stat.S_IWGRP | stat.S_IWOTH):
            raise OutputError(f"{flag}: {shown_path(text)} is read-only; refusing to replace it")
    suffixes = SUFFIXES.get(kind)
    if suffixes is not None and real.suffix.lower() not in suffixes:
        raise OutputError(
            f"{flag}: cannot tell the format of {shown_path(text)}; end the name with one of "
            f"{', '.join(suffixes)}"
        )
    return real


class Prepared:
    """An output written in full to its temporary file beside ``target`` (flushed,
    fsynced, given the target's mode), not yet in place: :meth:`commit` renames it over
    the target, :meth:`discard` removes it (nothing after a commit)."""

    def __init__(self, path: str, flag: str, target: Path, temporary: str) -> None:
        self.path, self.flag, self.target, self.temporary = path, flag, target, temporary

    def commit(self) -> None:
        """Rename the temporary file over the target (atomic) and make it durable."""
        try:
            fault_point("replace")
            os.replace(self.temporary, self.target)
        except OSError as exc:
            raise _write_error(self.flag, self.path, exc) from None
        self.temporary = ""
        fsync_directory(self.target.parent)

    def discard(self) -> None:
        if self.temporary:
            with contextlib.suppress(OSError):
                os.unlink(self.temporary)
            self.temporary = ""


def _write_error(flag: str, path: str, exc: OSError) -> OutputError:
    reason = exc.strerror or os.strerror(exc.errno or errno.EIO)
    return OutputError(f"{flag}: cannot write {shown_path(path)}: {reason}")


def prepare_output(
    path: str | os.PathLike[str],
    flag: str,
    write: Callable[[IO[bytes]], object],
    kind: str = "csv",
) -> Prepared:
    """The file ``path`` written with ``write(handle)`` (a binary handle) to a temporary
    file beside it, ready to :meth:`~Prepared.commit`; a failure at any stage removes
    the temporary file and leaves the target as it was."""
    target = check_output(path, flag, kind)
    remove_dead_temporaries(target)
    temporary = ""
    try:
        fault_point("open")
        prefix = f".{target.name}.{os.getpid()}."
        fd, temporary = tempfile.mkstemp(dir=target.parent, prefix=prefix, suffix=".tmp")
        with os.fdopen(fd, "wb") as handle:
            fault_point("write")
            write(handle)
            handle.flush()
            fault_point("fsync")
            os.fsync(handle.fileno())
        fault_point("chmod")
        keep_mode(temporary, target)
    except BaseException as exc:  # an interrupt midway too: no temporary file left
        if temporary:
            with contextlib.suppress(OSError):
                os.unlink(temporary)
        if isinstance(exc, OSError):
            raise _write_error(flag, os.fspath(path), exc) from None
        raise
    return Prepared(os.fspath(path), flag, target, temporary)


def write_output(
    path: str | os.PathLike[str],
    flag: str,
    write: Callable[[IO[bytes]], object],
    kind: str = "csv",
) -> Path:
    """Write the file ``path`` atomically with ``write(handle)`` (a binary handle); the
    target's mode and group are kept. Returns the real path written."""
    prepared = prepare_output(path, flag, write, kind)
    try:
        prepared.commit()
    finally:
        prepared.discard()
    return prepared.target


def write_text(path: str | os.PathLike[str], text: str, flag: str, kind: str = "csv") -> Path:
    """Write ``text`` (UTF-8) to ``path`` atomically."""
    return write_output(path, flag, lambda handle: handle.write(text.encode()), kind)


def streamed(
    chunks: Iterable[str], digest: hashlib._Hash | None = None
) -> Callable[[IO[bytes]], None]:
    """A writer of the texts ``chunks`` (UTF-8), one at a time as they are made, so that
    memory holds one chunk however long the file; ``digest`` (hashlib) is fed the bytes."""

    def write(handle: IO[bytes]) -> None:
        for chunk in chunks:
            fault_point("chunk")
            data = chunk.encode()
            if digest is not None:
                digest.update(data)
            handle.write(data)

    return write


def stream_text(
    path: str | os.PathLike[str], chunks: Iterable[str], flag: str, kind: str = "csv"
) -> Path:
    """Write the texts ``chunks`` (UTF-8) to ``path`` as they are made (:func:`streamed`);
    atomically all the same: they go into the temporary file, which replaces the target
    only after the last one. A failure midway, in writing a chunk or in making one,
    leaves the old file as it was."""
    return write_output(path, flag, streamed(chunks), kind)


def pid_alive(pid: int) -> bool:
    """Whether process ``pid`` exists (on this host)."""
    try:
        os.kill(pid, 0)
    except ProcessLookupError:
        return False
    except (PermissionError, OverflowError):
        return True
    return True


def temporary_owner(name: str, target: str) -> int | None:
    """The process that made the temporary ``name`` of ``target``, if ``name`` parses
    exactly as one (``.TARGET.PID.XXXXXXXX.tmp``, 8 characters of ``tempfile``'s or
    hexadecimal digits); None otherwise (another file's: the temporaries of ``a`` and of
    ``a.4194303`` both start with ``.a.``)."""
    prefix = f".{target}."
    if not (name.startswith(prefix) and name.endswith(".tmp")):
        return None
    found = re.fullmatch(r"([0-9]{1,10})\.[a-z0-9_]{8}", name[len(prefix) : -len(".tmp")])
    return int(found.group(1)) if found else None


def remove_dead_temporaries(target: Path) -> None:
    """Delete the temporary files of writers of ``target`` that were killed mid-write
    (``.NAME.PID.XXXX.tmp`` whose process is gone; regular files only, never a link)."""
    for temporary in target.parent.glob(f".{glob.escape(target.name)}.*.tmp"):
        pid = temporary_owner(temporary.name, target.name)
        if pid is not None and not pid_alive(pid) and temporary.is_file():
            if not temporary.is_symlink():
                temporary.unlink(missing_ok=True)


def keep_mode(temporary: str, target: Path) -> None:
    """Give ``temporary`` the mode, owner and group of ``target`` if it exists (as far as
    this process may), else the mode a new file gets under the umask."""
    try:
        status = os.stat(target)
    except FileNotFoundError:
        os.chmod(temporary, 0o666 & ~umask())
        return
    os.chmod(temporary, stat.S_IMODE(status.st_mode))
    try:
        os.chown(temporary, status.st_uid, status.st_gid)
    except PermissionError:  # not ours to give away: keep the group if we may
        with contextlib.suppress(PermissionError):
            os.chown(temporary, -1, status.st_gid)


def fsync_directory(directory: Path) -> None:
    """Make a rename in ``directory`` durable."""
    with contextlib.suppress(OSError):
        fd = os.open(directory, os.O_RDONLY)
        try:
            os.fsync(fd)
        finally:
            os.close(fd)
