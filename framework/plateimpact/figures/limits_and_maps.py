"""Figures of limits and outcome maps (matplotlib is imported here, only when drawing).

* :func:`plot_bands`: every line of a :class:`~plateimpact.limits.Limits` as a bar of its
  bands, with the ballistic and ricochet limits (or the critical ricochet obliquity)
  marked;
* :func:`plot_outcome_map`: the (impact speed, obliquity) plane coloured by regime, the
  located boundaries drawn over it and contours of exit speed;
* :func:`plot_limit_curves`: ballistic and ricochet limits against obliquity, for
  several plates.
"""

from __future__ import annotations

import math
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
from .style import figure, regime_colour, regime_key

_DEG = math.pi / 180.0


def _key(ax: Axes, regimes: Sequence[Regime], **kwargs: Any) -> None:
    ax.legend(handles=regime_key(regimes), fontsize="small", **kwargs)


def _model_line(model: dict[str, object]) -> str:
    return f"{model.get('resistance')} + {model.get('failure')}, {model.get('integrator')}"


def plot_bands(found: Limits, label: str) -> Figure:
    """One bar per line, coloured by band; limits marked (black: ballistic limit or
    critical ricochet obliquity, white: ricochet limit)."""
    fig, ax = figure(figsize=(8.0, 0.9 + 0.38 * len(found.lines)), layout="constrained")
    along_speed = found.axis != OBLIQUITY
    scale = 1.0 if along_speed else _DEG
    seen: set[Regime] = set()
    for k, line in enumerate(found.lines):
        for band in line.bands:
            seen.add(band.regime)
            ax.broken_barh(
                [(band.start / scale, band.width / scale)], (k - 0.4, 0.8),
                facecolors=regime_colour(band.regime),
            )  # fmt: skip
        marks = [(line.ballistic_limit, "k"), (line.ricochet_limit, "w")]
        if not along_speed:
            marks = [(line.critical_ricochet_obliquity, "k")]
        for at, colour in marks:
            if at is not None:
                ax.plot([at / scale] * 2, [k - 0.45, k + 0.45], color=colour, lw=2)
    ax.set_yticks(range(len(found.lines)))
    ax.set_yticklabels(
        [
            f"{line.fixed / _DEG:g}°" if along_speed else f"{line.fixed:g} m/s"
            for line in found.lines
        ]
    )
    ax.set_ylabel("impact obliquity" if along_speed else "impact speed")
    ax.set_xlabel("impact speed [m/s]" if along_speed else "impact obliquity [deg]")
    ax.set_xlim(found.lines[0].start / scale, found.lines[0].end / scale)
    ax.set_ylim(-0.6, len(found.lines) - 0.4)
    limits = "black: ballistic limit, white: ricochet limit" if along_speed else (
        "black: critical ricochet obliquity"
    )  # fmt: skip
    ax.set_title(f"{label}: outcome bands ({_model_line(found.model)}); {limits}", fontsize=9)
    _key(ax, sorted(seen), loc="upper center", bbox_to_anchor=(0.5, -0.22), ncol=5)
    return fig


def draw_outcome_map(ax: Axes, found: OutcomeMap, label: str) -> None:
    """The map of ``found`` on ``ax``: regimes, boundaries, exit-speed contours."""
    codes = [r.code for r in REGIMES]
    index = np.searchsorted(codes, found.regime)  # regime code -> colour index
    cmap = ListedColormap([regime_colour(r) for r in REGIMES])
    norm = BoundaryNorm(np.arange(len(REGIMES) + 1) - 0.5, len(REGIMES))
    degrees = found.obliquities / _DEG
    # A raster even in SVG and PDF (thousands of cells); boundaries and labels stay vector.
    ax.pcolormesh(found.speeds, degrees, index, cmap=cmap, norm=norm, shading="nearest",
                  rasterized=True)  # fmt: skip
    top = float(np.nanmax(found.exit_speed))
    levels = np.asarray(MaxNLocator(8).tick_values(0.0, top))[1:]
    levels = levels[levels < top]
    if levels.size:
        lines = ax.contour(found.speeds, degrees, found.exit_speed, levels=levels,
                           colors="k", linewidths=0.5, alpha=0.5)  # fmt: skip
        ax.clabel(lines, fontsize=6, fmt="%g m/s")
    for _, _, xs, ys in found.boundary_curves():
        ax.plot(xs, ys / _DEG, color="k", lw=1.2)
    ax.set_xlabel("impact speed [m/s]")
    ax.set_ylabel("impact obliquity [deg]")
    spacing = float(found.speeds[1] - found.speeds[0])
    ax.set_title(
        f"{label}: outcomes ({_model_line(found.limits.model)}); boundaries to "
        f"{found.limits.tolerance:g} m/s, grid {spacing:.3g} m/s; contours: exit speed",
        fontsize=8,
    )
    present = sorted({Regime.of_code(int(c)) for c in np.unique(found.regime)})
    _key(ax, present, loc="upper left")


def plot_outcome_map(maps: Sequence[tuple[str, OutcomeMap]]) -> Figure:
    """One panel per (label, map)."""
    fig, axes = figure(len(maps), 1, figsize=(8.0, 5.0 * len(maps)), layout="constrained",
                       squeeze=False)  # fmt: skip
    for ax, (label, found) in zip(axes[:, 0], maps, strict=True):
        draw_outcome_map(ax, found, label)
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
