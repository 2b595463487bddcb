"""Compiling a pair's program before a run needs it, so that no command waits for numba.

numba takes 10–25 s to compile a program, once per installation and pair (it is cached on
disk, :mod:`~plateimpact.solve.compiled.program`). Under ``engine="auto"`` a run never
waits for that: a pair whose program is not ready runs on the numpy path (the same
results, to round-off: tests/test_compiled.py) while one detached process compiles it
into the cache; the runs after it find it ready and run compiled. ``engine="compiled"``
and ``plateimpact compile`` compile in the foreground instead.

Whether a program is ready, failed or being compiled: :mod:`.cache`.
"""

from __future__ import annotations

import contextlib
import os
import subprocess
import sys
from importlib import import_module
from typing import TypeVar

from ...base.errors import PluginError
from ...model.failure import FailureModel
from ...model.resistance import ResistanceLaw
from . import program
from .cache import compile_lock

T = TypeVar("T")


def _name(cls: type) -> str:
    return f"{cls.__module__}:{cls.__qualname__}"


#: The write ends of the pipes the detached processes wait on: open until this process
#: ends (never closed here), so that they compile once it has.
_held: list[int] = []


def start(law: type[ResistanceLaw], failure: type[FailureModel]) -> bool:
    """Compile the pair's program in a detached process once this one has ended, unless a
    process already is compiling it; True if this call started one.

    The process waits for this one to end (the end of a pipe whose other end only this
    process holds) before compiling: this process keeps the numpy path for the pair
    anyway, and a compile beside it would slow it (on a 2-core machine the first
    ``reproduce`` took 34 s instead of 29 s)."""
    key = program.spec(law, failure).key
    with compile_lock(key, wait=False) as free:
        if not free:
            return False
    environment = dict(os.environ)
    # the child imports the plug-in classes by name: the parent's path finds them
    environment["PYTHONPATH"] = os.pathsep.join(p for p in sys.path if p)
    command = [sys.executable, "-m", __name__, _name(law), _name(failure)]
    waited, held = os.pipe() if os.name == "posix" else (-1, -1)
    if waited >= 0:
        command.append(str(waited))
    try:
        subprocess.Popen(  # noqa: S603 (this interpreter, our own module)
            command,
            stdin=subprocess.DEVNULL,
            stdout=subprocess.DEVNULL,
            stderr=subprocess.DEVNULL,
            start_new_session=True,
            env=environment,
            pass_fds=(waited,) if waited >= 0 else (),
        )
    finally:
        if waited >= 0:
            os.close(waited)
            _held.append(held)
    return True


def _load_class(name: str, base: type[T]) -> type[T]:
    """The class ``module:Qualname``, a subclass of ``base``."""
    module, _, qualname = name.partition(":")
    found: object = import_module(module)
    for part in qualname.split("."):
        found = getattr(found, part)
    if not (isinstance(found, type) and issubclass(found, base)):
        raise PluginError(f"{name} is not a {base.__name__}")
    return found


def compile_pairs(
    pairs: list[tuple[type[ResistanceLaw], type[FailureModel]]],
) -> list[tuple[str, str]]:
    """Compile (or load) each pair's program in this process, once per program; the
    status of each pair ("ready", or why not), in order."""
    from .building import build  # noqa: PLC0415 (numba is imported only here)

    done: list[tuple[str, str]] = []
    for law, failure in pairs:
        try:
            build(law, failure)
            done.append((f"{law.name} + {failure.name}", "ready"))
        except Exception as exc:  # noqa: BLE001 (reported, one line each)
            said = str(exc).strip().splitlines()
            done.append((f"{law.name} + {failure.name}", said[0] if said else type(exc).__name__))
    return done


def compiled_pairs(registry: object) -> list[tuple[type[ResistanceLaw], type[FailureModel]]]:
    """Every (resistance law, failure model) pair of ``registry`` that provides kernels."""
    names = registry.names  # type: ignore[attr-defined]
    get = registry.get  # type: ignore[attr-defined]
    laws = [get("resistance", n) for n in names("resistance")]
    failures = [get("failure", n) for n in names("failure")]
    return [
        (law, failure)
        for law in laws
        for failure in failures
        if law.stress_kernel is not None and failure.kernels is not None
    ]


def main(argv: list[str]) -> int:
    """The detached process: compile one pair's program (``module:Class`` of the law and
    of the failure model), once the process that started it has ended (the third
    argument: the pipe it waits on), and mark it ready or failed; at the lowest
    priority."""
    if hasattr(os, "nice"):
        os.nice(19)
    if len(argv) == 3:  # wait for the process that started this one to end
        with contextlib.suppress(OSError, ValueError):
            while os.read(int(argv[2]), 1):
                pass
    try:
        law = _load_class(argv[0], ResistanceLaw)  # type: ignore[type-abstract]
        failure = _load_class(argv[1], FailureModel)  # type: ignore[type-abstract]
        key = program.spec(law, failure).key
    except (ImportError, AttributeError, IndexError, PluginError, ValueError):
        return 2
    with compile_lock(key, wait=False) as free:
        if not free:
            return 0  # another process is compiling it
    reason = compile_pairs([(law, failure)])[0][1]
    return 0 if reason == "ready" else 1


if __name__ == "__main__":
    raise SystemExit(main(sys.argv[1:]))
