"""A writer that must be another process (killed at an injected point, racing the test for
a lock, crashing libhdf5), forked from the test's process: as separate as a subprocess,
without the second of CPU a new interpreter spends importing plateimpact."""

from __future__ import annotations

import contextlib
import faulthandler
import os
import signal
import subprocess
import sys
import tempfile
import traceback
import warnings
from collections.abc import Callable


class Forked:
    """``work()`` run in a child forked from this process, as separate a writer as a
    subprocess (its own descriptors, locks and module state; a kill or a crash ends it
    alone), with everything this process has imported. Its standard output and error
    are captured at file descriptors 1 and 2 (libhdf5's own messages too), warnings
    printed there as an interpreter prints them. A child still running after ``timeout``
    seconds is ended by SIGALRM (a hang fails the test instead of stopping the suite).
    Fork it before starting threads."""

    def __init__(self, work: Callable[[], object], timeout: int = 600) -> None:
        self.out, self.err = tempfile.TemporaryFile(), tempfile.TemporaryFile()
        self.pid = os.fork()
        if self.pid == 0:  # the child: leaves only through os._exit, never into pytest
            code = 1
            try:
                signal.signal(signal.SIGALRM, signal.SIG_DFL)
                signal.alarm(timeout)
                os.dup2(self.out.fileno(), 1)
                os.dup2(self.err.fileno(), 2)
                sys.stdout = open(1, "w", closefd=False)  # noqa: SIM115 (never closed)
                sys.stderr = open(2, "w", closefd=False)  # noqa: SIM115
                warnings.showwarning = _print_warning  # not into pytest's record
                faulthandler.disable()  # pytest's prints a crash to the terminal
                work()
                code = 0
            except SystemExit as exc:  # as the interpreter ends on it
                code = exc.code if isinstance(exc.code, int) else int(exc.code is not None)
                if not isinstance(exc.code, int | None):
                    print(exc.code, file=sys.stderr)
            except BaseException:  # noqa: BLE001 (the parent sees exit 1 and the traceback)
                traceback.print_exc()
            finally:
                with contextlib.suppress(BaseException):
                    sys.stdout.flush()
                    sys.stderr.flush()
                os._exit(code)

    def wait(self) -> subprocess.CompletedProcess[str]:
        """The child's end: returncode -N if signal N ended it, else its exit code (0:
        ``work`` returned; 1: it raised, the traceback in stderr), and what it printed."""
        status = os.waitpid(self.pid, 0)[1]
        printed = []
        for captured in (self.out, self.err):
            with captured:
                captured.seek(0)
                printed.append(captured.read().decode(errors="replace"))
        return subprocess.CompletedProcess(
            [], os.waitstatus_to_exitcode(status), printed[0], printed[1]
        )


def forked(work: Callable[[], object]) -> subprocess.CompletedProcess[str]:
    """``work()`` run to its end in a forked child (:class:`Forked`)."""
    return Forked(work).wait()


def _print_warning(message, category, filename, lineno, file=None, line=None) -> None:
    sys.stderr.write(warnings.formatwarning(message, category, filename, lineno, line))
