"""The one writer of a command's output: standard output for what the command prints,
standard error for its one-line errors and warnings.

Every command writes through the :class:`Writer` that ``main`` hands it: text is
flushed as it is written, so a standard output that cannot take it (a full device, a
closed pipe end, one closed before the start) is one ``StdoutError`` line and exit
code 2 for every command, never a traceback or Python's "Exception ignored" at exit.
"""

from __future__ import annotations

import contextlib
import os
import sys
from typing import TextIO

from ..base.untrusted import printable
from ..storage.output import OutputError


class StdoutError(OutputError):
    """Standard output cannot take what a command prints: a full device, a closed one."""


def _failed(exc: OSError) -> StdoutError:
    reason = exc.strerror or type(exc).__name__
    return StdoutError(f"standard output: cannot write: {reason}")


class Writer:
    """A command's output. Standard output and error are looked up at each write (a
    caller may have replaced them: a test's capture, ``contextlib.redirect_stdout``)."""

    def closed(self) -> bool:
        """Whether the command was started with standard output closed (``>&-``): Python
        then has no ``sys.stdout``, and the next file opened would take its descriptor."""
        if sys.stdout is None:
            return True
        try:
            descriptor = sys.stdout.fileno()
        except (AttributeError, OSError, ValueError):  # not a file: a caller's buffer
            return False
        try:
            os.fstat(descriptor)
        except OSError:
            return True
        return False

    def write(self, text: str) -> None:
        """``text`` as it is (CSV, JSON, help), flushed now: a standard output that cannot
        take it is a one-line ``StdoutError`` (a broken pipe stays BrokenPipeError:
        the reader left, which is no error)."""
        if sys.stdout is None:
            raise StdoutError("standard output is closed; redirect it (e.g. > /dev/null)")
        try:
            sys.stdout.write(text)
            sys.stdout.flush()
        except BrokenPipeError:
            raise
        except OSError as exc:
            raise _failed(exc) from None

    def say(self, text: object = "") -> None:
        """One or more lines of human-readable text (and a new line): every character a
        terminal would act on is escaped line by line (untrusted.printable), so that text
        from a file that reached it unescaped still prints inert."""
        lines = str(text).split("\n")
        self.write("\n".join(printable(line) for line in lines) + "\n")

    def flush(self) -> None:
        """Flush what a library printed past the writer; a failure is a StdoutError."""
        if sys.stdout is None:
            return
        try:
            sys.stdout.flush()
        except BrokenPipeError:
            raise
        except OSError as exc:
            raise _failed(exc) from None

    def discard(self) -> None:
        """After standard output failed: point its descriptor at /dev/null, so that what
        is still buffered does not fail again at exit (Python's "Exception ignored" and
        exit code 120). Only for a real file descriptor (not a caller's buffer)."""
        with contextlib.suppress(AttributeError, OSError, ValueError):
            descriptor = sys.stdout.fileno()
            null = os.open(os.devnull, os.O_WRONLY)
            try:
                os.dup2(null, descriptor)
            finally:
                os.close(null)

    def line_to_stderr(self, text: str, file: TextIO | None = None) -> None:
        """One line on standard error (or ``file``), escaped whole: an error, a warning."""
        stream = file or sys.stderr
        with contextlib.suppress(OSError, ValueError, AttributeError):  # nowhere to say it
            stream.write(printable(text) + "\n")
            stream.flush()

    def error(self, message: object) -> int:
        """The one-line error ``plateimpact: error: ...``; the exit code, 2."""
        self.line_to_stderr(f"plateimpact: error: {message}")
        return 2
