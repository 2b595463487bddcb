"""Writing a figure to a file, all of it or nothing, in the format its name says (PNG,
SVG, PDF, ...), through storage.output's writers."""

from __future__ import annotations

import os
from collections.abc import Callable
from pathlib import Path
from typing import IO

from matplotlib.figure import Figure

from ..storage.output import FIGURE_DPI, FIGURE_DPI_RANGE, write_output

#: Resolution of saved raster figures by default, and the range accepted [dots per inch].
DPI, DPI_RANGE = FIGURE_DPI, FIGURE_DPI_RANGE


def figure_writer(
    fig: Figure, path: str | os.PathLike[str], dpi: float = DPI
) -> Callable[[IO[bytes]], object]:
    """What writes ``fig`` to a binary handle in the format of ``path``'s extension (PNG,
    SVG, PDF, ...) at ``dpi`` [dots per inch] for a raster: a figure with a layout
    engine keeps its size (a PNG is ``dpi`` × its inches); one without is cropped to
    what is drawn. For storage.output's writers (:func:`save`, a set of outputs)."""
    if not DPI_RANGE[0] <= dpi <= DPI_RANGE[1]:  # also refuses NaN
        raise ValueError(f"dpi must be from {DPI_RANGE[0]:g} to {DPI_RANGE[1]:g}, got {dpi}")
    suffix = Path(path).suffix.lower().lstrip(".")
    crop = None if fig.get_layout_engine() else "tight"
    return lambda handle: fig.savefig(handle, format=suffix, dpi=dpi, bbox_inches=crop)


def save(fig: Figure, path: str | os.PathLike[str], flag: str = "figure", dpi: float = DPI) -> None:
    """Save a figure (:func:`figure_writer`), all of it or nothing: written beside the
    target and renamed over it (storage.output)."""
    write_output(path, flag, figure_writer(fig, path, dpi), kind="figure")
