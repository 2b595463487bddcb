"""Figures of limits and outcome maps (matplotlib is imported here, only when drawing).

* :func:`plot_bands`: every line of a :class:`~plateimpact.limits.Limits` as a bar of its
  bands, with the ballistic and ricochet limits (or the critical ricochet obliquity)
  marked;
* :func:`plot_outcome_map`: the (impact speed, obliquity) plane of each plate as an
  image coloured by regime, the located boundaries drawn over it, one panel per plate
  in a grid at journal width;
* :func:`plot_limit_curves`: ballistic and ricochet limits against obliquity, for
  several plates.
"""

from __future__ import annotations

import math
import textwrap
from collections.abc import Sequence
from typing import Any

import numpy as np
from matplotlib.axes import Axes
from matplotlib.colors import BoundaryNorm, ListedColormap
from matplotlib.figure import Figure
from matplotlib.ticker import MaxNLocator

from ..limits.lines import OBLIQUITY
from ..limits.maps import OutcomeMap
from ..limits.plate_limits import Limits
from ..limits.regimes import REGIMES, Regime
from .style import COLUMN_WIDTH, FONT, PAGE_WIDTH, SMALL, figure, regime_colour, regime_key

_DEG = math.pi / 180.0


def _model_line(model: dict[str, object]) -> str:
    return f"{model.get('resistance')} + {model.get('failure')}, {model.get('integrator')}"


#: How each limit is marked on the bars: solid black for the ballistic limit (or the
#: critical ricochet obliquity), dotted near-black for the ricochet limit. Both dark, so
#: that they show on every regime's colour and on paper; their key says which is which.
_LIMIT_MARKS: dict[str, dict[str, Any]] = {
    "ballistic limit": {"color": "k", "lw": 2.0, "ls": "-"},
    "ricochet limit": {"color": "0.1", "lw": 2.0, "ls": (0, (1, 1))},
    "critical ricochet obliquity": {"color": "k", "lw": 2.0, "ls": "-"},
}


def plot_bands(found: Limits, label: str) -> Figure:
    """One bar per line, coloured by band, at journal width; the limits marked (solid:
    ballistic limit or critical ricochet obliquity, dotted: ricochet limit), with one
    key below the axes for the regimes and the marks."""
    from matplotlib.lines import Line2D  # noqa: PLC0415

    fig, ax = figure(figsize=(PAGE_WIDTH, 1.3 + 0.3 * len(found.lines)), layout="constrained")
    along_speed = found.axis != OBLIQUITY
    scale = 1.0 if along_speed else _DEG
    seen: set[Regime] = set()
    marked: set[str] = set()
    for k, line in enumerate(found.lines):
        for band in line.bands:
            seen.add(band.regime)
            ax.broken_barh(
                [(band.start / scale, band.width / scale)], (k - 0.4, 0.8),
                facecolors=regime_colour(band.regime),
            )  # fmt: skip
        marks = [("ballistic limit", line.ballistic_limit), ("ricochet limit", line.ricochet_limit)]
        if not along_speed:
            marks = [("critical ricochet obliquity", line.critical_ricochet_obliquity)]
        for name, at in marks:
            if at is not None:
                marked.add(name)
                ax.plot([at / scale] * 2, [k - 0.45, k + 0.45], **_LIMIT_MARKS[name])
    ax.set_yticks(range(len(found.lines)))
    ax.set_yticklabels(
        [
            f"{line.fixed / _DEG:g}°" if along_speed else f"{line.fixed:g} m/s"
            for line in found.lines
        ]
    )
    ax.tick_params(labelsize=SMALL)
    ax.set_ylabel("impact obliquity" if along_speed else "impact speed [m/s]", fontsize=FONT)
    ax.set_xlabel("impact speed [m/s]" if along_speed else "impact obliquity [deg]",
                  fontsize=FONT)  # fmt: skip
    ax.set_xlim(found.lines[0].start / scale, found.lines[0].end / scale)
    ax.set_ylim(-0.6, len(found.lines) - 0.4)
    ax.set_title(f"{label}: outcome bands ({_model_line(found.model)})", fontsize=FONT)
    handles: list[Any] = list(regime_key(sorted(seen)))
    handles += [Line2D([], [], label=name, **_LIMIT_MARKS[name])
                for name in _LIMIT_MARKS if name in marked]  # fmt: skip
    fig.legend(handles=handles, loc="outside lower center", ncol=4, fontsize=SMALL,
               frameon=False)  # fmt: skip
    return fig


def cell_edges(centres: np.ndarray) -> np.ndarray:
    """The edges of cells centred on ``centres`` (increasing): half-way between
    neighbours, half a spacing beyond the ends (``shading="nearest"``)."""
    middles = (centres[1:] + centres[:-1]) / 2.0
    return np.concatenate([[2.0 * centres[0] - middles[0]], middles,
                           [2.0 * centres[-1] - middles[-1]]])  # fmt: skip


def _draw_map(ax: Axes, found: OutcomeMap) -> set[Regime]:
    """The cells of ``found`` as one image in the regime palette, and its located
    boundaries as black lines; the regimes present."""
    codes = [r.code for r in REGIMES]
    index = np.searchsorted(codes, found.regime)  # regime code -> colour index
    cmap = ListedColormap([regime_colour(r) for r in REGIMES])
    norm = BoundaryNorm(np.arange(len(REGIMES) + 1) - 0.5, len(REGIMES))
    # One image (nearest cells; uneven rows make a rectilinear image), a raster in SVG and
    # PDF too: thousands of cells drawn as one bitmap, not as thousands of paths.
    ax.pcolorfast(cell_edges(found.speeds), cell_edges(found.obliquities / _DEG), index,
                  cmap=cmap, norm=norm)  # fmt: skip
    for _, _, xs, ys in found.boundary_curves():  # located to the tolerance, not the grid
        ax.plot(xs, ys / _DEG, color="k", lw=0.8)
    ax.xaxis.set_major_locator(MaxNLocator(5))
    ax.yaxis.set_major_locator(MaxNLocator(5, steps=[1, 2, 3, 5, 10]))
    ax.tick_params(labelsize=SMALL, length=2.5, width=0.6, pad=2)
    return {Regime.of_code(int(c)) for c in np.unique(found.regime)}


def _failure(found: OutcomeMap) -> str:
    return f"{found.limits.model.get('failure')}"


def _details(found: OutcomeMap) -> str:
    """The model and the accuracy of a map, for its figure's title."""
    spacing = float(found.speeds[1] - found.speeds[0])
    return (
        f"{_model_line(found.limits.model)}; boundaries (black) located to "
        f"{found.limits.tolerance:g} m/s on a {spacing:.3g}-m/s grid"
    )


def draw_outcome_map(ax: Axes, found: OutcomeMap, label: str) -> None:
    """The map of ``found`` on ``ax``: the regimes as an image, the located boundaries,
    titled ``label`` with the failure model in small print, axis labels in m/s and deg,
    and a key of the regimes present."""
    present = _draw_map(ax, found)
    ax.set_title(label, loc="left", fontsize=FONT, pad=3)
    ax.set_title(_failure(found), loc="right", fontsize=SMALL, color="0.35", pad=3)
    ax.set_xlabel("impact speed [m/s]", fontsize=FONT)
    ax.set_ylabel("impact obliquity [deg]", fontsize=FONT)
    ax.legend(handles=regime_key(present), fontsize=SMALL, loc="upper left")


def _map_grid(count: int) -> tuple[int, int]:
    """(rows, columns) of ``count`` panels: one column for one map, two for two or four,
    else three."""
    columns = 1 if count == 1 else 2 if count in (2, 4) else 3
    return math.ceil(count / columns), columns


def plot_outcome_map(maps: Sequence[tuple[str, OutcomeMap]]) -> Figure:
    """One panel per (label, map) in a grid of up to three columns, for print: 7.2 in
    wide (3.5 in for one map), each panel titled with its label and, in small print,
    its failure model; the axes labelled (m/s, deg) at the grid's edges, where the tick
    labels are when the maps share one grid, and the regime key below."""
    nrows, ncols = _map_grid(len(maps))
    width = PAGE_WIDTH if ncols > 1 else COLUMN_WIDTH
    panel = 0.62 * width / ncols  # height of a panel's frame [in]
    grids = {(m.speeds.tobytes(), m.obliquities.tobytes()) for _, m in maps}
    share = len(grids) == 1  # one grid: one pair of axes, tick labels at the edges only
    fig, axes = figure(nrows, ncols, figsize=(width, nrows * (panel + 0.35) + 0.95),
                       layout="constrained", squeeze=False, sharex=share, sharey=share)  # fmt: skip
    present: set[Regime] = set()
    for n, (ax, (label, found)) in enumerate(zip(axes.flat, maps, strict=False)):
        present |= _draw_map(ax, found)
        # A long label (a plate file's path) wraps short of the small print beside it.
        room = int((width / ncols - 0.5) * 15) - len(_failure(found))  # 7-pt chars
        ax.set_title(textwrap.fill(label, max(room, 8)), loc="left", fontsize=FONT, pad=3)
        ax.set_title(_failure(found), loc="right", fontsize=SMALL, color="0.35", pad=3)
        if n + ncols >= len(maps):  # no panel below: its speeds are labelled
            ax.tick_params(labelbottom=True)
            ax.set_xlabel("impact speed [m/s]", fontsize=FONT)
        if n % ncols == 0:
            ax.set_ylabel("impact obliquity [deg]", fontsize=FONT)
    for ax in axes.flat[len(maps) :]:
        fig.delaxes(ax)
    # Five regimes fit one row of the page's width; a column's width takes two per row.
    columns = len(present) if ncols > 1 else min(len(present), 2)
    fig.legend(handles=regime_key(present), loc="outside lower center", fontsize=SMALL,
               frameon=False, ncols=columns)  # fmt: skip
    details = "; ".join(dict.fromkeys(_details(found) for _, found in maps))
    heading = "Outcome maps" if len(maps) > 1 else "Outcome map"
    title = textwrap.fill(f"{heading}: {details}", int(width * 16))  # 16 chars per in
    fig.suptitle(title, fontsize=FONT)
    return fig


def plot_limit_curves(maps: Sequence[tuple[str, OutcomeMap]]) -> Figure:
    """Ballistic limit (solid) and ricochet limit (dashed) against obliquity, one colour
    per plate."""
    fig, ax = figure(figsize=(8.0, 5.0), layout="constrained")
    for k, (label, found) in enumerate(maps):
        colour = f"C{k}"
        degrees = found.obliquities / _DEG
        ballistic = [line.ballistic_limit for line in found.limits.lines]
        ricochet = [line.ricochet_limit for line in found.limits.lines]
        ax.plot(degrees, [np.nan if v is None else v for v in ballistic], color=colour,
                label=f"{label} ballistic limit")  # fmt: skip
        ax.plot(degrees, [np.nan if v is None else v for v in ricochet], color=colour, ls="--",
                label=f"{label} ricochet limit")  # fmt: skip
    ax.set_xlabel("impact obliquity [deg]")
    ax.set_ylabel("impact speed [m/s]")
    first = maps[0][1].limits
    ax.set_title(
        f"Ballistic limit (solid) and ricochet limit (dashed); {_model_line(first.model)}; "
        f"to {first.tolerance:g} m/s",
        fontsize=9,
    )
    ax.legend(fontsize="small", ncol=2)
    return fig
