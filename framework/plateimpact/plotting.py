"""Figures in the layout of the report: outcome curves against impact speed, craters.

matplotlib is imported here only, so the rest of plateimpact does not need a display
or pay the import time. Functions draw on axes you pass and return them.
"""

from __future__ import annotations

from collections.abc import Sequence
from typing import TYPE_CHECKING

import matplotlib

matplotlib.use("Agg")  # files, not windows: studies and CI run headless

import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402
from matplotlib.axes import Axes  # noqa: E402

from .crater import CraterSection  # noqa: E402
from .results import BatchResult, Outcome, Trajectory  # noqa: E402

if TYPE_CHECKING:
    from .study import StudyResults

OUTCOME_SHADES = {
    Outcome.RICOCHET: "#dbe9f6",
    Outcome.EMBEDMENT: "#f3e3c3",
    Outcome.PERFORATION: "#dcefd8",
}


def shade_outcomes(ax: Axes, speeds: np.ndarray, outcome: np.ndarray) -> None:
    """Shade the impact-speed ranges [m/s] of each outcome, split half-way between grid points."""
    edges = np.concatenate([[speeds[0]], 0.5 * (speeds[1:] + speeds[:-1]), [speeds[-1]]])
    start = 0
    for i in range(1, len(speeds) + 1):
        if i == len(speeds) or outcome[i] != outcome[start]:
            code = Outcome(int(outcome[start]))
            ax.axvspan(edges[start], edges[i], color=OUTCOME_SHADES[code], lw=0, zorder=0)
            start = i


def plot_exit_curves(
    axes: Sequence[Axes],
    speeds: np.ndarray,
    result: BatchResult,
    *,
    label: str | None = None,
    shade: bool = True,
    **style: object,
) -> Sequence[Axes]:
    """Exit speed and exit obliquity against impact speed (the report's Figures 11–44).

    ``axes`` are (speed axes, obliquity axes); ``speeds`` the impact speeds [m/s] of the
    scenes of ``result``, in order. Embedments have exit speed 0; their obliquity is the
    direction at rest.
    """
    speed_ax, obliquity_ax = axes
    if shade:
        for ax in axes:
            shade_outcomes(ax, speeds, result.outcome)
    speed_ax.plot(speeds, result.exit_speed, label=label, **style)
    obliquity_ax.plot(speeds, np.degrees(result.exit_obliquity), label=label, **style)
    speed_ax.set_ylabel("exit speed [m/s]")
    obliquity_ax.set_ylabel("exit obliquity [deg]")
    obliquity_ax.set_ylim(0, 185)
    for ax in axes:
        ax.set_xlabel("impact speed [m/s]")
        ax.set_xlim(speeds[0], speeds[-1])
    return axes


def plot_crater(
    ax: Axes,
    section: CraterSection,
    *,
    trajectory: Trajectory | None = None,
    radius: float | None = None,
    label: str | None = None,
    **style: object,
) -> Axes:
    """The crater floor, depth downward, in mm from the entry point; with ``trajectory``
    and ``radius``, the centre's path and the sphere at first contact, deepest, last."""
    ax.plot(section.lateral * 1e3, section.depth * 1e3, label=label, **style)
    ax.axhline(0.0, color="0.3", lw=0.8)
    if trajectory is not None and radius is not None:
        shift = section.impact_point
        centre_y = (trajectory.lateral + shift) * 1e3
        centre_x = (trajectory.penetration - radius) * 1e3
        ax.plot(centre_y, centre_x, ls=":", color="0.5", lw=0.8)
        angles = np.linspace(0, 2 * np.pi, 181)
        for i in (0, int(np.argmax(trajectory.penetration)), -1):
            ax.plot(
                centre_y[i] + radius * 1e3 * np.cos(angles),
                centre_x[i] + radius * 1e3 * np.sin(angles),
                color="0.6",
                lw=0.6,
            )
    ax.set_xlabel("along the plate from entry [mm]")
    ax.set_ylabel("depth [mm]")
    ax.set_aspect("equal")
    if not ax.yaxis_inverted():
        ax.invert_yaxis()
    return ax


def save(fig: plt.Figure, path: str) -> None:
    """Save and close a figure."""
    fig.savefig(path, dpi=120, bbox_inches="tight")
    plt.close(fig)


def plot_study(results: StudyResults, runs: Sequence[str] | None = None) -> plt.Figure:
    """Exit speed and exit obliquity against impact speed for every plate × obliquity of a
    study: one column per (plate, obliquity), the first run solid with its outcome ranges
    shaded, further runs dashed on top (the report's comparison layout, Figures 30–31)."""
    study = results.study
    runs = list(runs or results.runs)
    labels = np.array(study.plate_labels)
    obliquity = np.round(np.degrees(study.scenes.impact_obliquity), 6)
    panels = [
        (label, ob)
        for label in dict.fromkeys(study.plate_labels)
        for ob in sorted(set(obliquity[labels == label]))
    ]
    fig, axes = plt.subplots(
        2,
        len(panels),
        figsize=(3.2 * len(panels), 6),
        sharex="col",
        squeeze=False,
        layout="constrained",
    )
    for column, (label, ob) in enumerate(panels):
        index = np.flatnonzero((labels == label) & (obliquity == ob))
        index = index[np.argsort(study.scenes.impact_speed[index])]
        speeds = study.scenes.impact_speed[index]
        for k, run in enumerate(runs):
            part = results[run].take(index)
            style = {"color": f"C{k}", "ls": "-" if k == 0 else "--"}
            plot_exit_curves(axes[:, column], speeds, part, label=run, shade=k == 0, **style)
        axes[0, column].set_title(f"{label}, {ob:g}°", fontsize=9)
        axes[0, column].set_xlabel("")
        if column:
            for ax in axes[:, column]:
                ax.set_ylabel("")
    axes[0, 0].legend(fontsize=8)
    fig.suptitle(f"{study.name}: ricochet | embedment | perforation ranges shaded ({runs[0]})")
    return fig
