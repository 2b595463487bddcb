"""One writer per archive: a lock file naming the writing process, and atomic renames."""

from __future__ import annotations

import contextlib
import os
import socket
from collections.abc import Iterator
from pathlib import Path

from ..errors import ArchiveError


def _pid_alive(pid: int) -> bool:
    try:
        os.kill(pid, 0)
    except ProcessLookupError:
        return False
    except PermissionError:
        return True
    return True


def check_not_busy(path: Path, lock_path: Path) -> None:
    """Refuse an archive whose lock names a live process other than this one."""
    try:
        pid_text, host = lock_path.read_text().split()[:2]
        pid = int(pid_text)
    except (OSError, ValueError):
        return
    if pid != os.getpid() and (host != socket.gethostname() or _pid_alive(pid)):
        raise ArchiveError(
            f"archive {path} is being written by process {pid} on {host}; "
            f"wait for it to finish (or remove {lock_path} if that process is gone)"
        )


@contextlib.contextmanager
def locked(path: Path, lock_path: Path) -> Iterator[None]:
    """Hold the lock of ``path``; a lock left by a dead process is taken over."""
    for _ in range(2):
        try:
            fd = os.open(lock_path, os.O_CREAT | os.O_EXCL | os.O_WRONLY, 0o644)
        except FileExistsError:
            check_not_busy(path, lock_path)  # raises if the writer lives; else it is stale
            lock_path.unlink(missing_ok=True)
            continue
        with os.fdopen(fd, "w") as handle:
            handle.write(f"{os.getpid()} {socket.gethostname()}\n")
        break
    else:
        raise ArchiveError(f"archive {path}: cannot take the lock {lock_path}")
    try:
        yield
    finally:
        lock_path.unlink(missing_ok=True)


def fsync_directory(directory: Path) -> None:
    """Make a rename in ``directory`` durable."""
    with contextlib.suppress(OSError):
        fd = os.open(directory, os.O_RDONLY)
        try:
            os.fsync(fd)
        finally:
            os.close(fd)
