"""The two runs of a :class:`~.ranges.Comparison` overlaid, outcome changes shaded: drawn
as the study figures draw runs (:func:`~.exit_curves.plot_exit_curves`: one line per
stretch of one regime, none across an outcome change, embedments not drawn), at
journal width."""

from __future__ import annotations

import numpy as np
from matplotlib.figure import Figure
from matplotlib.lines import Line2D
from matplotlib.patches import Patch

from ..comparison.ranges import Comparison, ComparisonRow
from ..limits.lines import SPEED
from .exit_curves import plot_exit_curves
from .style import FONT, PAGE_WIDTH, RUN_STYLES, SMALL, figure

#: Shades of the ranges whose outcome differs, one per change (A's regime -> B's).
CHANGE_SHADES = ("#f6d2cc", "#d5e5f5", "#f7e6c4", "#e4d9f0", "#d6eedb", "#e8e8e8")


def _edges(x: np.ndarray) -> np.ndarray:
    """Span edges around each point: half-way to its neighbours, ±1 for a lone point."""
    if x.size == 1:
        return np.array([x[0] - 1.0, x[0] + 1.0])
    middle = 0.5 * (x[1:] + x[:-1])
    return np.concatenate([[x[0]], middle, [x[-1]]])


def _draw_row(
    axes: np.ndarray, comparison: Comparison, row: ComparisonRow, shades: dict[str, str]
) -> None:
    """Exit speed (top) and exit obliquity (bottom) of both runs along one row."""
    scenes = comparison.scenes
    x = (
        scenes.impact_speed[row.index]
        if row.axis == SPEED
        else np.degrees(scenes.impact_obliquity[row.index])
    )
    edges = _edges(x)
    position = {int(scene): k for k, scene in enumerate(row.index)}
    for change in row.ranges:
        first, last = position[int(change.index[0])], position[int(change.index[-1])]
        for ax in axes:
            shade = shades[change.pair]
            ax.axvspan(edges[first], edges[last + 1], color=shade, lw=0, zorder=0)
    order = np.argsort(x, kind="stable")
    for result, style in (
        (comparison.result_a, RUN_STYLES[0]),
        (comparison.result_b, RUN_STYLES[1]),
    ):
        plot_exit_curves(list(axes), x[order], result.take(row.index[order]), **style)
    if not axes[1].lines:  # every sphere of both runs embedded: say so, not an empty panel
        axes[1].text(0.5, 0.5, "no exit: embedded in both runs", transform=axes[1].transAxes,
                     ha="center", va="center", fontsize=SMALL, color="0.35")  # fmt: skip
    fixed = f"{np.degrees(row.fixed):g}°" if row.axis == SPEED else f"{row.fixed:g} m/s"
    axes[0].set_title(f"{row.plate}, {fixed}", fontsize=FONT)
    axes[1].set_xlabel("impact speed [m/s]" if row.axis == SPEED else "impact obliquity [deg]",
                       fontsize=FONT)  # fmt: skip
    axes[1].set_ylim(-5, 185)  # an exit along the normal (0 deg) off the frame's edge
    for ax in axes:
        ax.tick_params(labelsize=SMALL)
    if x.size > 1:
        axes[1].set_xlim(x[0], x[-1])


def plot_comparison(comparison: Comparison) -> Figure:
    """Exit speed and exit obliquity of run A (solid) and run B (dashed) along every row
    of the comparison (a column each), the ranges whose outcome differs shaded, one shade
    per change; exit speeds and obliquities only where the sphere leaves the plate."""
    rows = comparison.rows()
    pairs = dict.fromkeys(change.pair for row in rows for change in row.ranges)
    shades = {pair: CHANGE_SHADES[k % len(CHANGE_SHADES)] for k, pair in enumerate(pairs)}
    fig, axes = figure(
        2,
        len(rows),
        figsize=(PAGE_WIDTH, 4.2),
        sharex="col",
        squeeze=False,
        layout="constrained",
    )
    for column, row in enumerate(rows):
        _draw_row(axes[:, column], comparison, row, shades)
    axes[0, 0].set_ylabel("exit speed [m/s]", fontsize=FONT)
    axes[1, 0].set_ylabel("exit obliquity [deg]", fontsize=FONT)
    legend = [
        Line2D([], [], label=comparison.run_a, **RUN_STYLES[0]),
        Line2D([], [], label=comparison.run_b, **RUN_STYLES[1]),
        *(Patch(color=shade, label=pair) for pair, shade in shades.items()),
    ]
    fig.legend(handles=legend, loc="outside lower center", ncols=min(len(legend), 3),
               fontsize=SMALL, frameon=False)  # fmt: skip
    fig.suptitle(f"{comparison.run_b} (dashed) against {comparison.run_a} (solid)",
                 fontsize=FONT)  # fmt: skip
    return fig
