"""The compiled programs' cache state beside each program file: ``.ready`` once it compiled,
``.failed`` (the reason, one line) if compiling it failed, and ``.lock``, held (``flock``) by
the process compiling it, so that concurrent processes (pytest-xdist workers, a pool, two
commands) compile a program once and the others wait for it or leave it be."""

from __future__ import annotations

import contextlib
from collections.abc import Iterator
from pathlib import Path
from typing import NamedTuple

from ...model.failure import FailureModel
from ...model.resistance import ResistanceLaw
from . import program

try:
    import fcntl
except ImportError:  # not POSIX: no lock, at worst a program compiled twice at once
    fcntl = None  # type: ignore[assignment]


class Status(NamedTuple):
    """A pair's program: its digest, whether it is ready, and why compiling it failed
    (empty if it did not)."""

    key: str
    ready: bool
    failure: str


def marker(key: str, suffix: str) -> Path:
    """The program's file with ``suffix`` ("ready", "failed", "lock", "py")."""
    return program.cache_directory() / f"program_{key}.{suffix}"


def status(law: type[ResistanceLaw], failure: type[FailureModel]) -> Status:
    """The pair's program as the cache holds it (no numba import). Raises PluginError
    (no kernels) or PackageNotFoundError (no numba)."""
    key = program.spec(law, failure).key
    failed = marker(key, "failed")
    reason = failed.read_text(errors="replace").strip()[:300] if failed.exists() else ""
    return Status(key, marker(key, "ready").exists(), reason)


@contextlib.contextmanager
def compile_lock(key: str, *, wait: bool = True) -> Iterator[bool]:
    """Hold the program's lock (waiting for it if ``wait``); yields False if another
    process holds it and ``wait`` is False."""
    path = marker(key, "lock")
    path.parent.mkdir(parents=True, exist_ok=True)
    with open(path, "a") as handle:
        if fcntl is None:
            yield True
            return
        try:
            fcntl.flock(handle, fcntl.LOCK_EX | (0 if wait else fcntl.LOCK_NB))
        except BlockingIOError:
            yield False
            return
        try:
            yield True
        finally:
            fcntl.flock(handle, fcntl.LOCK_UN)


def mark(key: str, failure: str = "") -> None:
    """Record that the program compiled (or, with ``failure``, why it did not)."""
    program.cache_directory().mkdir(parents=True, exist_ok=True)
    if failure:
        marker(key, "failed").write_text(failure.strip().splitlines()[0][:300] + "\n")
    else:
        marker(key, "failed").unlink(missing_ok=True)
        marker(key, "ready").touch()
