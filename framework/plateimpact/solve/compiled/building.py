"""Building a pair's compiled program in this process: generated, compiled by numba (or
loaded from its cache) under the program's lock, and marked ready or failed."""

from __future__ import annotations

from types import ModuleType

import numpy as np

from ...base.errors import PluginError
from ...model.events import EVENTS
from ...model.failure import FailureModel
from ...model.resistance import ResistanceLaw
from . import cache, program, scene


class ProgramUnavailable(Exception):
    """The pair's program could not be built, loaded or compiled: the reason, one line."""


def signature_arguments() -> tuple[np.ndarray, ...]:
    """Arguments of the types :func:`integrate_compiled` passes a program, for no scenes:
    a call with them compiles exactly what a batch runs (tested)."""
    events = len(EVENTS)
    return (
        np.empty((0, 6)), np.empty((0, 4)), np.empty((0, 4)), np.empty((0, 1)),
        np.empty((0, 2)), np.empty(1), np.empty((1, 1)), np.empty(1), np.empty(1),
        np.empty((1, 1)), np.zeros(5), np.zeros(10, np.int64), np.zeros(events, np.int64),
        np.zeros(events, np.bool_), np.empty((0, scene.FLOAT_RESULTS)),
        np.empty((0, scene.COUNTS), np.int64), np.empty((0, 6)), np.empty(0, np.int64),
    )  # fmt: skip


_built: dict[tuple[type, type], ModuleType] = {}


def build(law: type[ResistanceLaw], failure: type[FailureModel]) -> ModuleType:
    """The pair's program, compiled in this process or loaded from numba's cache, under
    the program's lock (:mod:`.cache`), and marked ready; ProgramUnavailable (and the
    program marked failed, where numba failed) if it cannot be."""
    if (law, failure) in _built:
        return _built[law, failure]
    try:
        key = program.spec(law, failure).key
        with cache.compile_lock(key):
            compiled = program.program(law, failure)
            try:
                compiled.run(0, 0, 1, *signature_arguments())  # compiles, or loads the cache
            except Exception as exc:  # numba's errors: the numpy path runs instead
                said = str(exc).strip().splitlines()
                reason = f"compiling failed ({type(exc).__name__}: {said[0] if said else ''})"
                cache.mark(key, reason)
                raise ProgramUnavailable(reason) from exc
    except (ImportError, OSError, PluginError) as exc:
        raise ProgramUnavailable(f"{type(exc).__name__}: {exc}") from exc
    cache.mark(key)
    _built[law, failure] = compiled
    return compiled
