"""What the command prints when something other than the user's input goes wrong.

A warning of plateimpact's own (a plug-in package skipped) is one line. An internal
error (a bug: any exception that is not a PlateImpactError) is one line naming the
exception and the file that holds its full traceback, so that a user sees what happened
and has something to attach to a bug report, without 30 lines of stack on the terminal.
"""

from __future__ import annotations

import datetime as dt
import os
import shlex
import tempfile
import traceback
from collections.abc import Sequence
from pathlib import Path
from typing import Protocol, TextIO

from ..base.errors import PlateImpactWarning
from ..base.untrusted import printable
from .writer import Writer


class ShowWarning(Protocol):
    """The signature of ``warnings.showwarning``."""

    def __call__(
        self,
        message: Warning | str,
        category: type[Warning],
        filename: str,
        lineno: int,
        file: TextIO | None = None,
        line: str | None = None,
    ) -> None: ...


def one_line_warnings(shown_before: ShowWarning, out: Writer) -> ShowWarning:
    """A ``warnings.showwarning`` for the command: plateimpact's warnings as one line
    through ``out``, the rest (numpy's, a library's) passed to ``shown_before``."""

    def show(
        message: Warning | str,
        category: type[Warning],
        filename: str,
        lineno: int,
        file: TextIO | None = None,
        line: str | None = None,
    ) -> None:
        if issubclass(category, PlateImpactWarning):
            out.line_to_stderr(f"plateimpact: warning: {message}", file)
        else:
            shown_before(message, category, filename, lineno, file, line)

    return show


def traceback_directories() -> list[Path]:
    """Where a traceback file goes: the user's cache directory (``$XDG_CACHE_HOME``,
    else ``~/.cache``), then the system's temporary directory."""
    cache = os.environ.get("XDG_CACHE_HOME") or ""
    base = Path(cache) if os.path.isabs(cache) else Path.home() / ".cache"
    return [base / "plateimpact", Path(tempfile.gettempdir())]


def write_traceback(exc: BaseException, argv: Sequence[str]) -> Path:
    """The full traceback of ``exc``, with the command line and versions, in a new file."""
    from ..provenance.metadata import versions  # noqa: PLC0415 (only on a bug)
    from ..registry.discovery import first_line  # noqa: PLC0415

    try:
        found = ", ".join(f"{name} {version}" for name, version in versions().items())
    except Exception:  # the report must not fail on what it only adds
        found = "unknown"
    text = (
        f"plateimpact internal error at {dt.datetime.now(dt.UTC).isoformat()}\n"
        f"command: {shlex.join(['plateimpact', *argv])}\n"
        f"versions: {found}\n\n" + "".join(traceback.format_exception(exc))
    )
    failures = []
    for directory in traceback_directories():
        try:
            directory.mkdir(parents=True, exist_ok=True)
            fd, path = tempfile.mkstemp(dir=directory, prefix="traceback-", suffix=".txt")
            with os.fdopen(fd, "w") as handle:
                handle.write(text)
            return Path(path)
        except OSError as error:
            failures.append(f"{directory}: {first_line(error)}")
    raise OSError("; ".join(failures))


def report_internal_error(exc: Exception, argv: Sequence[str], out: Writer) -> int:
    """Print the one line of an internal error; the exit code (1)."""
    from ..registry.discovery import first_line  # noqa: PLC0415 (only on a bug)

    try:
        where = f"the traceback is in {write_traceback(exc, argv)}"
    except OSError as error:
        where = f"the traceback could not be written ({error}); run with --debug to see it"
    out.line_to_stderr(f"plateimpact: internal error: {printable(first_line(exc))}; {where}")
    return 1
