"""Outputs that belong together land together: a CSV and the JSON beside it that says
what it holds, a plate file and the figure of its fit.

:func:`write_together` writes every file of the set to its temporary file first
(storage.output: written, flushed, fsynced, given its target's mode), so that a failure
in any of them (a full disk, a bad figure) leaves every target as it was. Only then are
the temporary files renamed over their targets, one after another, with SIGINT, SIGTERM
and SIGHUP held back (:func:`signals_deferred`): an interrupt lands before the first
rename or after the last, never between, and takes effect as soon as the set is in place. A
rename that fails midway puts back the files already replaced (from hard links made
before the first rename). Only SIGKILL or a power cut can split a set; a JSON sidecar
therefore records the SHA-256 of the file it describes (``csv_sha256``), so that a
reader can tell a pair that does not belong together.
"""

from __future__ import annotations

import contextlib
import os
import secrets
import signal
import threading
from collections.abc import Callable, Iterator, Sequence
from pathlib import Path
from typing import IO, Any

import attrs

from .output import OutputError, Prepared, check_output, fault_point, prepare_output

#: The signals held back while a set of outputs is renamed into place.
DEFERRED = (signal.SIGINT, signal.SIGTERM, signal.SIGHUP)


@attrs.frozen
class Output:
    """One file of a set: where (``path``, refused in messages as ``flag``), what
    (``write(handle)``, a binary handle) and the kind of name it must have (``csv``,
    ``json``, ``figure``: storage.output.SUFFIXES)."""

    path: str | os.PathLike[str]
    flag: str
    write: Callable[[IO[bytes]], object]
    kind: str = "csv"


@contextlib.contextmanager
def signals_deferred() -> Iterator[None]:
    """Hold back :data:`DEFERRED` until the block ends, then deliver them as they would
    have been (KeyboardInterrupt for SIGINT, the end of the process for SIGTERM).

    A handler that only records them is installed for the block, rather than the
    signals blocked with ``pthread_sigmask``: a signal sent to the process goes to any
    thread that does not block it (a library's worker thread), and would act at once.
    Python runs handlers in the main thread only: elsewhere this is a no-op."""
    if threading.current_thread() is not threading.main_thread():
        yield
        return
    caught: list[int] = []

    def hold(signum: int, frame: object) -> None:
        caught.append(signum)

    before: dict[signal.Signals, Any] = {}
    for number in DEFERRED:
        with contextlib.suppress(OSError, ValueError):
            before[number] = signal.signal(number, hold)
    try:
        yield
    finally:
        for number, handler in before.items():
            # None: a handler installed outside Python, which cannot be put back as it was
            signal.signal(number, signal.SIG_DFL if handler is None else handler)
        for held in dict.fromkeys(caught):
            signal.raise_signal(held)


def write_together(outputs: Sequence[Output]) -> list[Path]:
    """Write ``outputs`` so that they land together (the module's description); returns
    the real paths written. Every target is checked before any is written."""
    for output in outputs:
        check_output(output.path, output.flag, output.kind)
    prepared: list[Prepared] = []
    try:
        for output in outputs:
            prepared.append(prepare_output(output.path, output.flag, output.write, output.kind))
        with signals_deferred():
            _commit_all(prepared)
    finally:
        for one in prepared:
            one.discard()
    return [one.target for one in prepared]


def _commit_all(prepared: Sequence[Prepared]) -> None:
    """Rename every prepared file into place; on a failure, put back those done."""
    kept = {one.target: _keep(one.target) for one in prepared}
    existed = {target: target.exists() for target in kept}
    done: list[Prepared] = []
    try:
        for one in prepared:
            one.commit()
            done.append(one)
    except OutputError:
        for one in reversed(done):
            _put_back(one.target, kept[one.target], existed[one.target])
        raise
    finally:
        for link in kept.values():
            if link is not None:
                with contextlib.suppress(OSError):
                    os.unlink(link)


def _keep(target: Path) -> Path | None:
    """A hard link to the file at ``target`` (named as a temporary file of this process,
    so that a writer after a crash removes it), or None: no file, or no hard links."""
    if not target.exists():
        return None
    link = target.parent / f".{target.name}.{os.getpid()}.{secrets.token_hex(4)}.tmp"
    try:
        fault_point("keep")
        os.link(target, link)
    except OSError:
        return None
    return link


def _put_back(target: Path, link: Path | None, existed: bool) -> None:
    """Undo a rename into ``target``: the kept old file back, or no file if none was."""
    with contextlib.suppress(OSError):
        if link is not None:
            os.replace(link, target)
        elif not existed:
            os.unlink(target)
