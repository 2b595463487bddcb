"""A progress bar for long runs (tqdm), silent off a terminal unless asked for."""

from __future__ import annotations

from tqdm.auto import tqdm


def progress_bar(total: int, label: str, show: bool | None) -> tqdm:
    """A context-managed bar over ``total`` scene runs; ``show=None``: on a TTY only."""
    return tqdm(total=total, desc=label, unit="scene", disable=None if show is None else not show)
