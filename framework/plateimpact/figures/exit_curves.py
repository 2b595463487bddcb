"""Exit speed and exit obliquity against impact speed, in the layout of the report's
Figures 11-44: the curves and outcome strip of one run (:func:`plot_exit_curves`,
:func:`plot_outcome_strip`), and a study's figure of every plate and obliquity
(:func:`plot_study`).
"""

from __future__ import annotations

import math
import textwrap
from collections.abc import Sequence
from typing import TYPE_CHECKING, Any

import numpy as np
from matplotlib.axes import Axes
from matplotlib.figure import Figure
from matplotlib.lines import Line2D

from ..limits.regimes import Regime, regime_codes
from ..model.results import BatchResult, Outcome
from .style import (
    COLUMN_WIDTH,
    FONT,
    MAX_COLUMNS,
    PAGE_WIDTH,
    RUN_STYLES,
    SMALL,
    regime_colour,
    regime_key,
)

if TYPE_CHECKING:
    from ..study.study import StudyResults


def _stretches(codes: np.ndarray) -> list[slice]:
    """The runs of equal consecutive values of ``codes``, as slices."""
    cuts = np.concatenate([[0], np.flatnonzero(np.diff(codes)) + 1, [codes.size]])
    return [slice(int(a), int(b)) for a, b in zip(cuts[:-1], cuts[1:], strict=True)]


def plot_exit_curves(
    axes: Sequence[Axes | None],
    speeds: np.ndarray,
    result: BatchResult,
    *,
    label: str | None = None,
    **style: Any,
) -> Sequence[Axes | None]:
    """Exit speed [m/s] and exit obliquity [deg] against impact speed [m/s] (the
    report's Figures 11-44) on (speed axes, obliquity axes); either may be None.

    ``speeds`` are the impact speeds of the scenes of ``result``, in increasing order.
    Each stretch of scenes with one regime is its own line, so no line joins two outcomes
    (nor a ricochet off an intact plate to one off a failed plate); a stretch of one scene
    is a dot. Embedded spheres have no exit and are not drawn: :func:`plot_outcome_strip`
    shows where they are.
    """
    speed_ax, obliquity_ax = axes
    codes = regime_codes(result)
    for part in _stretches(codes):
        if Regime.of_code(codes[part.start]).outcome is Outcome.EMBEDMENT:
            continue
        marker = "." if part.stop - part.start == 1 else ""
        for ax, value in (
            (speed_ax, result.exit_speed),
            (obliquity_ax, np.degrees(result.exit_obliquity)),
        ):
            if ax is not None:
                ax.plot(speeds[part], value[part], marker=marker, ms=2, label=label, **style)
        label = "_nolegend_"  # one legend entry per run
    return axes


def plot_outcome_strip(
    ax: Axes, speeds: np.ndarray, results: Sequence[tuple[str, BatchResult]]
) -> set[Regime]:
    """One bar per run (first on top), coloured by regime along the impact speeds [m/s]
    (ranges split half-way between grid points); returns the regimes drawn. A range of
    one scene stays visible: each bar is edged in its own colour."""
    edges = np.concatenate([[speeds[0]], 0.5 * (speeds[1:] + speeds[:-1]), [speeds[-1]]])
    drawn = set()
    for row, (_, result) in enumerate(results):
        codes = regime_codes(result)
        for part in _stretches(codes):
            regime = Regime.of_code(codes[part.start])
            drawn.add(regime)
            start, end = edges[part.start], edges[part.stop]
            colour = regime_colour(regime)
            ax.broken_barh([(start, end - start)], (row - 0.4, 0.8), facecolors=colour,
                           edgecolors=colour, linewidth=0.6)  # fmt: skip
    ax.set_ylim(len(results) - 0.5, -0.5)
    ax.set_yticks(range(len(results)), [name for name, _ in results])
    ax.tick_params(axis="y", length=0)
    return drawn


def _along_the_normal(parts: Sequence[BatchResult]) -> list[float] | None:
    """The exit obliquities [deg] of these scenes when all are 0 or 180 (normal
    incidence: the sphere leaves along the normal; none if every sphere embedded), else
    None."""
    exits = np.concatenate(
        [np.degrees(p.exit_obliquity[p.outcome != Outcome.EMBEDMENT]) for p in parts]
    )
    trivial = np.isclose(exits, 0.0, atol=1e-6) | np.isclose(exits, 180.0, atol=1e-6)
    return sorted({float(round(v)) for v in exits}) if trivial.all() else None


def _grid_shape(count: int) -> tuple[int, int]:
    """(rows, columns) of ``count`` panels: at most MAX_COLUMNS columns, rows as even as
    they can be."""
    rows = math.ceil(count / MAX_COLUMNS)
    return rows, math.ceil(count / rows)


def study_panels(results: StudyResults) -> list[tuple[str, float, np.ndarray]]:
    """(plate label, obliquity [deg], scene indices sorted by impact speed) per panel."""
    study = results.study
    labels = np.array(study.plate_labels)
    obliquity = np.round(np.degrees(study.scenes.impact_obliquity), 6)
    panels = []
    for label in dict.fromkeys(study.plate_labels):
        for ob in sorted(set(obliquity[labels == label])):
            index = np.flatnonzero((labels == label) & (obliquity == ob))
            panels.append((label, ob, index[np.argsort(study.scenes.impact_speed[index])]))
    return panels


def short_run_name(run: str, study: str) -> str:
    """A run's name without its study's prefix (the study is in the title)."""
    return run.removeprefix(f"{study}/")


def plot_study(results: StudyResults, runs: Sequence[str] | None = None) -> Figure:
    """Exit speed and exit obliquity against impact speed for every plate × obliquity of a
    study (the report's Figures 11-44; the comparison layout of Figures 30-31 when there
    are several runs), drawn at journal width: 7.2 in, 3.5 in for one panel.

    One panel per (plate, obliquity), at most four to a row: exit speed over exit
    obliquity over an outcome strip, one bar per run coloured by regime; the key below.
    Runs are black solid, red dashed, blue dotted, ... Curves break where the regime
    changes; embedments appear in the strips only. At normal incidence, where every exit
    obliquity is 0° (or 180°), the obliquity frame says so instead of a flat line.
    """
    study = results.study
    runs = list(runs or results.runs)
    panels = study_panels(results)
    nrows, ncols = _grid_shape(len(panels))
    curve, strip = 1.1, 0.08 + 0.12 * len(runs)  # heights [in]
    width = PAGE_WIDTH if ncols > 1 else COLUMN_WIDTH
    height = nrows * (2 * curve + strip + 0.45) + 0.6
    fig = Figure(figsize=(width, height), layout="constrained")
    grid = fig.add_gridspec(3 * nrows, ncols, height_ratios=[curve, curve, strip] * nrows)
    shared: list[Axes] = []  # the first panel's exit-speed and exit-obliquity axes
    regimes: set[Regime] = set()
    for n, (label, ob, index) in enumerate(panels):
        row, column = divmod(n, ncols)
        speed_ax = fig.add_subplot(grid[3 * row, column], sharey=shared[0] if shared else None)
        obliquity_ax = fig.add_subplot(
            grid[3 * row + 1, column], sharex=speed_ax, sharey=shared[1] if shared else None
        )
        strip_ax = fig.add_subplot(grid[3 * row + 2, column], sharex=speed_ax)
        shared = shared or [speed_ax, obliquity_ax]
        parts = [(short_run_name(run, study.name), results[run].take(index)) for run in runs]
        speeds = study.scenes.impact_speed[index]
        regimes |= _draw_panel((speed_ax, obliquity_ax, strip_ax), speeds, parts, ob == 0)
        speed_ax.set_title(f"{label}, {ob:g}°", fontsize=FONT, pad=3)
        if column == 0:
            speed_ax.set_ylabel("exit speed [m/s]", fontsize=FONT)
            obliquity_ax.set_ylabel("exit obliquity [deg]", fontsize=FONT)
        else:
            for ax in (speed_ax, obliquity_ax, strip_ax):
                ax.tick_params(labelleft=False)
        if n + ncols >= len(panels):  # no panel below
            strip_ax.set_xlabel("impact speed [m/s]", fontsize=FONT)
    lines = [
        Line2D(
            [], [], lw=1.0, label=short_run_name(run, study.name), **RUN_STYLES[k % len(RUN_STYLES)]
        )
        for k, run in enumerate(runs)
    ]
    entries = [*lines, *regime_key(regimes)]
    fig.legend(handles=entries, loc="outside lower center", fontsize=SMALL, frameon=False,
               ncol=len(entries) if len(entries) <= 5 else math.ceil(len(entries) / 2))  # fmt: skip
    plates = ", ".join(dict.fromkeys(study.plate_labels))
    title = f"{plates} (study {study.name})" + (f": {study.description}" * bool(study.description))
    fig.suptitle(textwrap.fill(title, int(width * 16)), fontsize=FONT + 1)  # 16 chars per in
    return fig


def _draw_panel(
    axes: tuple[Axes, Axes, Axes],
    speeds: np.ndarray,
    parts: Sequence[tuple[str, BatchResult]],
    normal_incidence: bool,
) -> set[Regime]:
    """One panel of :func:`plot_study`: the runs' exit curves and outcome strip."""
    speed_ax, obliquity_ax, strip_ax = axes
    along = _along_the_normal([part for _, part in parts]) if normal_incidence else None
    for k, (run, part) in enumerate(parts):
        style = RUN_STYLES[k % len(RUN_STYLES)]
        plot_exit_curves([speed_ax, None if along is not None else obliquity_ax], speeds,
                         part, label=run, lw=1.0, **style)  # fmt: skip
    if along is not None:
        angles = " or ".join(f"{v:g}°" for v in along)
        note = f"every exit obliquity is {angles}" if along else "no sphere leaves the plate"
        obliquity_ax.text(0.5, 0.5, f"normal incidence:\n{note}",
                          transform=obliquity_ax.transAxes, ha="center", va="center",
                          fontsize=SMALL, color="0.35")  # fmt: skip
    drawn = plot_outcome_strip(strip_ax, speeds, parts)
    if len(parts) == 1:
        strip_ax.set_yticks([])
    obliquity_ax.set_ylim(-8, 188)
    obliquity_ax.set_yticks([0, 45, 90, 135, 180])
    if speeds[-1] > speeds[0]:  # one speed: matplotlib's own margins
        strip_ax.set_xlim(speeds[0], speeds[-1])
    for ax in axes:
        ax.tick_params(labelsize=SMALL, length=2.5, width=0.6, pad=2)
    for ax in axes[:2]:
        ax.tick_params(labelbottom=False)
    return drawn
