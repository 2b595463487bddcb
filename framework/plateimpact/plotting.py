"""Figures in the layout of the report: outcome curves against impact speed, craters.

matplotlib is imported here only, so the rest of plateimpact does not need a display
or pay the import time. Figures are made as :class:`matplotlib.figure.Figure` objects,
not through pyplot: nothing here touches the user's backend or pyplot's state, so the
functions work the same in a script, a notebook and an interactive session. Functions
draw on axes you pass and return them; :func:`figure` gives a figure and its axes.
"""

from __future__ import annotations

import os
from collections.abc import Mapping, Sequence
from pathlib import Path
from typing import TYPE_CHECKING, Any

import matplotlib
import numpy as np
from matplotlib.axes import Axes
from matplotlib.figure import Figure

from .results import BatchResult, CraterSection, Outcome, Trajectory
from .storage.output import write_output

if TYPE_CHECKING:
    from .calibration import DriFit
    from .storage.shots import Shots
    from .study import StudyResults

#: Resolution of saved figures [dots per inch].
DPI = 120


def figure(nrows: int = 1, ncols: int = 1, **kwargs: Any) -> tuple[Figure, Any]:
    """A new figure (outside pyplot) and its axes, as ``pyplot.subplots`` returns them."""
    fig = Figure(figsize=kwargs.pop("figsize", None), layout=kwargs.pop("layout", None))
    return fig, fig.subplots(nrows, ncols, **kwargs)


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
    **style: Any,
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
    **style: Any,
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


def plot_calibration(
    ax: Axes,
    shots: Shots,
    dri: DriFit,
    curves: Mapping[str, tuple[np.ndarray, np.ndarray]],
) -> Axes:
    """Residual speed against impact speed, the layout of the report's Figure 11: the
    shots (open markers: no perforation), the DRI fit (eq 40, dashed) and model curves.

    ``curves`` maps a label to (impact speeds [m/s], residual speeds [m/s]).
    """
    perforated = shots.perforated
    ax.plot(shots.impact_speed[perforated], shots.residual_speed[perforated], "ko", label="shots")
    if not perforated.all():
        ax.plot(
            shots.impact_speed[~perforated],
            shots.residual_speed[~perforated],
            "ko",
            mfc="none",
            label="shots, no perforation",
        )
    for label, (speeds, residual) in curves.items():
        ax.plot(speeds, residual, lw=1.2, label=label)
    speeds = next(iter(curves.values()))[0] if curves else shots.impact_speed
    grid = np.linspace(speeds.min(), speeds.max(), 300)
    ax.plot(
        grid,
        dri.residual_speed(grid),
        "k--",
        lw=1,
        label=f"DRI fit: R = {dri.R:.4g}, V0 = {dri.V0:.4g} m/s",
    )
    ax.set_xlabel("impact speed [m/s]")
    ax.set_ylabel("residual speed [m/s]")
    ax.set_ylim(bottom=0)
    ax.legend(fontsize="small", loc="upper left")
    return ax


def save(fig: Figure, path: str | os.PathLike[str], flag: str = "figure") -> None:
    """Save a figure, its format from the file's extension (PNG, SVG, PDF, ...), all of it
    or nothing: written beside the target and renamed over it (storage.output)."""
    suffix = Path(path).suffix.lower().lstrip(".")
    write_output(
        path,
        flag,
        lambda handle: fig.savefig(handle, format=suffix, dpi=DPI, bbox_inches="tight"),
        kind="figure",
    )


def plot_study(results: StudyResults, runs: Sequence[str] | None = None) -> Figure:
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
    fig, axes = figure(
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


#: What :func:`plot_study_paths` can draw from a run.
PATH_KINDS = ("trajectory", "crater")


def _panels(results: StudyResults) -> list[tuple[str, float, np.ndarray]]:
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


def _pick(speeds: np.ndarray, wanted: Sequence[float] | None, count: int) -> np.ndarray:
    """Positions in ``speeds`` (sorted) nearest each wanted speed, or ``count`` spread evenly."""
    if wanted is None:
        return np.unique(
            np.linspace(0, speeds.size - 1, min(count, speeds.size)).round().astype(int)
        )
    return np.unique([int(np.argmin(np.abs(speeds - w))) for w in wanted])


def plot_study_paths(
    results: StudyResults,
    runs: Sequence[str] | None = None,
    *,
    kind: str = "crater",
    speeds: Sequence[float] | None = None,
    count: int = 6,
) -> Figure:
    """Crater sections (eqs 31–39) or the centre's trajectories, one panel per plate ×
    obliquity of a study, one line per impact speed [m/s] (``speeds``: the scenes nearest
    these; default ``count`` spread over the range); the first run solid, others dashed.

    Craters need runs made with ``craters=True``, trajectories ``record_trajectory=True``.
    Depth is drawn downward in mm: craters from the entry point, trajectories from the
    first-contact point, with the plate's back surface dotted.
    """
    if kind not in PATH_KINDS:
        raise ValueError(f"kind must be one of {', '.join(PATH_KINDS)}, got {kind!r}")
    study = results.study
    runs = list(runs or results.runs)
    for run in runs:
        if (results[run].craters if kind == "crater" else results[run].trajectory) is None:
            need = "craters=True" if kind == "crater" else "record_trajectory=True"
            raise ValueError(f"run {run!r} has no {kind} data: run the study with {need}")
    panels = _panels(results)
    fig, axes = figure(
        len(panels), 1, figsize=(8, 2.6 * len(panels)), squeeze=False, layout="constrained"
    )
    for ax, (label, ob, index) in zip(axes[:, 0], panels, strict=True):
        chosen = index[_pick(study.scenes.impact_speed[index], speeds, count)]
        colours = matplotlib.colormaps["viridis"](np.linspace(0.0, 0.9, chosen.size))
        thickness = study.scenes.thickness[chosen[0]] * 1e3
        for k, run in enumerate(runs):
            result = results[run]
            for colour, i in zip(colours, chosen, strict=True):
                style = {"color": colour, "ls": "-" if k == 0 else "--", "lw": 1.2}
                name = f"{study.scenes.impact_speed[i]:g} m/s, {Outcome(result.outcome[i]).label}"
                if kind == "crater":
                    section = result.crater_of(i)
                    assert section is not None  # checked above
                    ax.plot(section.lateral * 1e3, section.depth * 1e3, label=name, **style)
                else:
                    path = result.trajectory_of(i)
                    assert path is not None  # checked above
                    centre = (path.penetration - study.scenes.radius[i]) * 1e3
                    ax.plot(path.lateral * 1e3, centre, label=name, **style)
        ax.axhline(0.0, color="0.3", lw=0.8)
        ax.axhline(thickness, color="0.3", lw=0.8, ls=":")
        ax.set_title(f"{label}, {ob:g}° ({', '.join(runs)})", fontsize=9)
        ax.set_xlabel("along the plate [mm]")
        ax.set_ylabel("depth [mm]" if kind == "crater" else "centre depth [mm]")
        ax.set_aspect("equal", adjustable="datalim")
        ax.invert_yaxis()
        ax.legend(fontsize=7, loc="upper left", bbox_to_anchor=(1.01, 1.0))
    what = "crater sections" if kind == "crater" else "trajectories of the centre"
    fig.suptitle(f"{study.name}: {what}")
    return fig
