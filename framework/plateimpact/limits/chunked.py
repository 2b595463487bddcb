"""Scenes run a chunk at a time, as a sweep streams its grid: what a search keeps of each
scene (a regime code, an exit speed) is what grows with its size, never a whole batch's
results, and a progress bar advances with every chunk.

A scene's result does not depend on its batch, so chunking changes nothing but memory
and the progress shown (tests/test_work_bounds.py checks it bit for bit).
"""

from __future__ import annotations

from collections.abc import Callable, Iterator
from concurrent.futures import Executor

import numpy as np

from ..model.batch import SceneBatch
from ..model.results import BatchResult
from ..run.simulation import DEFAULT_CHUNK_SIZE, Simulation

#: Scenes run in one batch: numpy's per-step overhead is spread over this many already
#: (a sweep runs 10,000 at a time at the speed of one batch), and their results, some
#: 100 bytes a scene, stay near a megabyte.
RUN_CHUNK = 10_000


def run_chunked(
    simulation: Simulation,
    batch_of: Callable[[np.ndarray], SceneBatch],
    size: int,
    executor: Executor | None = None,
) -> Iterator[tuple[slice, BatchResult]]:
    """Run scenes 0 .. ``size`` − 1, RUN_CHUNK at a time: ``batch_of(index)`` builds the
    scenes at ``index``; yields (the slice of scenes, their results)."""
    for start in range(0, size, RUN_CHUNK):
        where = slice(start, min(start + RUN_CHUNK, size))
        batch = batch_of(np.arange(where.start, where.stop))
        yield where, simulation.run_batch(batch, executor=executor, chunk_size=DEFAULT_CHUNK_SIZE)
