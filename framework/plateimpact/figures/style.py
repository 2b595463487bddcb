"""The page every figure is drawn for: journal widths and font sizes, one colour per
regime and one line style per run, and a new figure outside pyplot.

Figures are made as :class:`matplotlib.figure.Figure` objects, not through pyplot:
nothing here touches the user's backend or pyplot's state, so the functions work the
same in a script, a notebook and an interactive session. Functions draw on axes you pass
and return them; :func:`figure` gives a figure and its axes.
"""

from __future__ import annotations

import math
import textwrap
from collections.abc import Sequence
from typing import Any

import numpy as np
from matplotlib.artist import Artist
from matplotlib.figure import Figure
from matplotlib.patches import Patch

from ..limits.regimes import REGIMES, Regime


def figure(nrows: int = 1, ncols: int = 1, **kwargs: Any) -> tuple[Figure, Any]:
    """A new figure (outside pyplot) and its axes, as ``pyplot.subplots`` returns them."""
    fig = Figure(figsize=kwargs.pop("figsize", None), layout=kwargs.pop("layout", None))
    return fig, fig.subplots(nrows, ncols, **kwargs)


#: Journal widths [in]: one column, two columns (the page).
COLUMN_WIDTH, PAGE_WIDTH = 3.5, 7.2
#: Font sizes [pt] of figures drawn at journal width: labels and titles, ticks and keys.
FONT, SMALL = 7.0, 6.0
#: The most columns of panels a study figure has; more obliquities make more rows.
MAX_COLUMNS = 4

#: One colour per regime, shared by the family figures' outcome strips and the outcome
#: maps (figures.limits_and_maps); the thin-plate band (ricochet after failure) stands out.
REGIME_COLOURS = {
    REGIMES[0]: "#4c72b0",  # ricochet
    REGIMES[1]: "#a05fc0",  # ricochet after failure
    REGIMES[2]: "#dd8452",  # embedment
    REGIMES[3]: "#e6c85a",  # embedment after failure
    REGIMES[4]: "#55a868",  # perforation
}
#: Line colours and styles of a study's runs, in order (black and dashed read in print).
RUN_STYLES: list[dict[str, Any]] = [
    {"color": "k", "ls": "-"},
    {"color": "C3", "ls": "--"},
    {"color": "C0", "ls": ":"},
    {"color": "C2", "ls": "-."},
    {"color": "C4", "ls": (0, (5, 1))},
]


def regime_colour(regime: Regime) -> str:
    return REGIME_COLOURS.get(regime, "#999999")


def regime_key(regimes: Sequence[Regime] | set[Regime]) -> list[Patch]:
    """Legend handles: one coloured patch per regime present, in the order of REGIMES."""
    return [Patch(color=regime_colour(r), label=r.label) for r in REGIMES if r in regimes]


def small_print(fig: Figure, text: str, width: float) -> None:
    """What produced ``fig`` (plate, model, samples, version), in small grey print along
    its foot, wrapped to its ``width`` [in]; a strip is kept for it below what the
    layout engine places (a figure drawn with ``layout="constrained"``)."""
    lines = textwrap.fill(text, int(width * 21))  # some 21 5-pt characters per inch
    strip = ((lines.count("\n") + 1) * (SMALL - 1) * 1.3 / 72.0 + 0.04) / fig.get_figheight()
    fig.get_layout_engine().set(rect=(0.0, strip, 1.0, 1.0 - strip))  # type: ignore[union-attr, call-arg]
    fig.text(0.5, 0.01 / fig.get_figheight(), lines, fontsize=SMALL - 1, color="0.35",
             ha="center", va="bottom")  # fmt: skip


def panel_grid(
    count: int, panel_width: float, row_height: float, foot: float, columns: int = MAX_COLUMNS
) -> tuple[Figure, np.ndarray]:
    """A figure of ``count`` panels in rows of at most ``columns``, each
    ``panel_width`` wide (the figure at most the page) and ``row_height`` high, with
    ``foot`` [in] for a key and titles; its axes, flat."""
    nrows = math.ceil(count / columns)
    ncols = math.ceil(count / nrows)
    fig = Figure(figsize=(min(PAGE_WIDTH, panel_width * ncols), row_height * nrows + foot),
                 layout="constrained")  # fmt: skip
    return fig, np.atleast_1d(fig.subplots(nrows, ncols, squeeze=False)).ravel()


def shared_key(fig: Figure, axes: np.ndarray, count: int) -> None:
    """One key below the first ``count`` panels, one entry per kind of mark from
    whichever panel has it; the panels beyond ``count`` hidden."""
    key: dict[str, Artist] = {}
    for ax in axes[:count]:
        for handle, label in zip(*ax.get_legend_handles_labels(), strict=True):
            key.setdefault(label, handle)
    fig.legend(list(key.values()), list(key), loc="outside lower center", ncols=3,
               fontsize=SMALL, frameon=False)  # fmt: skip
    for ax in axes[count:]:
        ax.set_visible(False)
