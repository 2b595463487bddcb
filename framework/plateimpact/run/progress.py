"""Progress bars for long runs (tqdm, on standard error): on a terminal only, and only
once a run has lasted :data:`DELAY` seconds, so that short runs, pipes and files see
nothing. Never on standard output, which carries results."""

from __future__ import annotations

from collections.abc import Iterator
from contextlib import contextmanager
from contextvars import ContextVar

from tqdm.auto import tqdm

#: Seconds a run must last before its bar appears.
DELAY = 2.0

#: The bar that batches run inside :func:`reporting_scenes` advance.
_listening: ContextVar[tqdm | None] = ContextVar("plateimpact_progress", default=None)


def progress_bar(total: int | None, label: str, show: bool | None, unit: str = "scene") -> tqdm:
    """A context-managed bar over ``total`` scene runs (or other ``unit``; None: a count
    without a total); ``show=None``: on a terminal only; either way only after
    :data:`DELAY` seconds."""
    return tqdm(
        total=total,
        desc=label,
        unit=unit,
        disable=None if show is None else not show,
        delay=DELAY,
    )


@contextmanager
def reporting_scenes(
    label: str, total: int | None = None, show: bool | None = None
) -> Iterator[tqdm]:
    """A bar advanced by every batch run inside the block (:meth:`Simulation.run_batch`
    reports to it): progress for work whose batches are run deep inside a search, as the
    limits finder's passes and the calibration's iterations are."""
    with progress_bar(total, label, show) as bar:
        token = _listening.set(bar)
        try:
            yield bar
        finally:
            _listening.reset(token)


def report_scenes(count: int) -> None:
    """``count`` more scenes run: advance the bar of the enclosing
    :func:`reporting_scenes` block, if there is one."""
    bar = _listening.get()
    if bar is not None:
        bar.update(count)
