"""One writer per archive file at a time, across the threads of a process and across
processes, keyed on the file's real path (a symlink and its target share one lock).

Threads of one process queue on a :class:`threading.Lock`; processes on an advisory
``flock`` of the lock file beside the archive (``ARCHIVE.lock``). The kernel releases a
``flock`` when its process dies, so a killed writer never leaves a stale lock; the lock
file itself stays (deleting it would let a waiting process lock a file that no longer
exists while a third creates a new one). It names the last writer, for messages.
A writer that finds the archive busy waits, up to a bound, and says so once.

The lock file may have come with the archive (a tarball holding ``ARCHIVE.lock``), so
it is opened without following a symlink (``O_NOFOLLOW``) and written only once
``fstat`` shows a regular file with one link: a shipped ``a.h5.lock -> ~/notes.txt``,
or a hard link to the notes, is refused with one line and never written.
"""

from __future__ import annotations

import contextlib
import errno
import fcntl
import math
import os
import socket
import stat
import threading
import time
import warnings
from collections.abc import Iterator
from pathlib import Path

from ..base.errors import ArchiveError, ArchiveWaitWarning
from ..base.untrusted import printable

#: How often a waiting writer looks again [s].
POLL = 0.05
#: What a busy archive's message says to wait longer. The wait decides only where a
#: finished run is stored (the archive, or a side archive the message names), never its
#: values.
WAIT_SETTING = " (Archive(path, wait=SECONDS) waits longer; inf: as long as it takes)"

_THREAD_LOCKS: dict[Path, threading.Lock] = {}
_GUARD = threading.Lock()


class ArchiveBusyError(ArchiveError):
    """The archive stayed locked by another writer longer than the writer could wait."""


def _thread_lock(real: Path) -> threading.Lock:
    with _GUARD:
        return _THREAD_LOCKS.setdefault(real, threading.Lock())


def holder(fd: int) -> str:
    """Who last took the lock, as the open lock file says ("process 123 on host")."""
    try:
        pid, host = os.pread(fd, 256, 0).decode().split()[:2]
        return f"process {int(pid)} on {printable(host, 64)}"
    except (OSError, ValueError):
        return "another writer"


def _open_lock(lock_path: Path, flags: int) -> int:
    """The lock file, opened without following a link and checked, on the descriptor,
    to be a regular file with one link (OSError if it cannot be opened, ArchiveError if
    it is not one we may write)."""
    fd = os.open(lock_path, flags | os.O_NOFOLLOW | os.O_NONBLOCK | os.O_CLOEXEC, 0o644)
    status = os.fstat(fd)
    if not stat.S_ISREG(status.st_mode) or status.st_nlink != 1:
        os.close(fd)
        what = (
            "a second name (hard link) of another file"
            if stat.S_ISREG(status.st_mode)
            else ("not a regular file")
        )
        raise ArchiveError(
            f"the lock file {lock_path} is {what}; refusing to write it (remove it: an "
            "archive's lock is an ordinary file of its own)"
        )
    return fd


def busy(lock_path: Path) -> bool:
    """Whether a live writer holds the lock (never blocks, never follows a link)."""
    try:
        fd = _open_lock(lock_path, os.O_RDONLY)
    except (OSError, ArchiveError):
        return False
    try:
        fcntl.flock(fd, fcntl.LOCK_SH | fcntl.LOCK_NB)
    except BlockingIOError:
        return True
    except OSError:
        return False
    finally:
        os.close(fd)  # closing drops the shared lock taken to look
    return False


@contextlib.contextmanager
def locked(path: Path, real: Path, lock_path: Path, wait: float) -> Iterator[None]:
    """Hold the write lock of the archive whose real path is ``real`` (``path`` as the
    user named it, for messages), waiting up to ``wait`` seconds (inf: as long as it
    takes) for another writer; :class:`ArchiveBusyError` if it is still busy then."""
    deadline = time.monotonic() + wait
    thread_lock = _thread_lock(real)
    if not thread_lock.acquire(blocking=False):
        _announce(path, "another thread of this process")
        if not thread_lock.acquire(timeout=-1 if math.isinf(wait) else max(wait, 0.0)):
            raise ArchiveBusyError(
                f"archive {path} stayed busy with another thread of this process for {wait:g} s"
                f"{WAIT_SETTING}"
            )
    try:
        try:
            fd = _open_lock(lock_path, os.O_RDWR | os.O_CREAT)
        except OSError as exc:
            symlink = exc.errno == errno.ELOOP
            reason = "it is a symbolic link; refusing to follow it" if symlink else exc.strerror
            raise ArchiveError(
                f"archive {path}: cannot open its lock {lock_path}: {reason}"
            ) from None
        except ArchiveError as exc:
            raise ArchiveError(f"archive {path}: {exc}") from None
        try:
            announced = False
            while True:
                try:
                    fcntl.flock(fd, fcntl.LOCK_EX | fcntl.LOCK_NB)
                    break
                except BlockingIOError:
                    if time.monotonic() >= deadline:
                        raise ArchiveBusyError(
                            f"archive {path} stayed busy ({holder(fd)} writing it) for "
                            f"{wait:g} s{WAIT_SETTING}"
                        ) from None
                    if not announced:
                        _announce(path, holder(fd))
                        announced = True
                    time.sleep(POLL)
            with contextlib.suppress(OSError):  # who holds it, for messages: a full disk
                os.ftruncate(fd, 0)  # must not keep a writer from the lock it holds
                os.pwrite(fd, f"{os.getpid()} {socket.gethostname()}\n".encode(), 0)
            yield
        finally:
            os.close(fd)  # releases the flock
    finally:
        thread_lock.release()


def _announce(path: Path, who: str) -> None:
    warnings.warn(
        f"archive {path} is being written by {who}; waiting for it",
        ArchiveWaitWarning,
        stacklevel=4,
    )
