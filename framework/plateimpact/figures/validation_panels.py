"""The figure of a validation: the shots over the model's curves, as the report lays its
measurements over Figures 11-44 (matplotlib is imported only here)."""

from __future__ import annotations

import math
from typing import Any

import numpy as np
from matplotlib.figure import Figure
from matplotlib.lines import Line2D

from ..base.errors import ShotDataError
from ..experiment.validation import MEASURED, ValidationReport, measured_classes
from ..model.batch import SceneBatch
from ..run.simulation import Simulation
from ..storage.shots import Shots
from .exit_curves import plot_exit_curves, plot_outcome_strip
from .style import FONT, MAX_COLUMNS, PAGE_WIDTH, SMALL, regime_key

#: Model-curve points per obliquity.
CURVE_POINTS = 300
#: A marker per measured outcome; go/no-go shots as a plus (perforated) or a cross.
MARKERS = dict(zip(MEASURED, ("o", "s", "^", "P", "X"), strict=True))
#: Edge colour of shots the model agrees with, and of those it does not.
AGREES, DISAGREES = "k", "#d62728"
#: Measured obliquities scatter about the nominal one: a panel holds the shots of one
#: obliquity to the nearest degree, and the figure at most MAX_PANELS panels.
MAX_PANELS = 16


def panel_obliquities(shots: Shots) -> np.ndarray:
    """The obliquity of each shot's panel [rad]: its own, to the nearest degree."""
    return np.radians(np.round(np.degrees(shots.impact_obliquity)))


def check_panels(shots: Shots) -> None:
    """Refuse (ShotDataError) shots at more obliquities than a figure has panels."""
    count = np.unique(panel_obliquities(shots)).size
    if count > MAX_PANELS:
        raise ShotDataError(
            f"{shots.source}: shots at {count} obliquities (to the nearest degree); the "
            f"figure draws at most {MAX_PANELS}"
        )


def validation_figure(
    report: ValidationReport,
    simulation: Simulation,
    *,
    title: str | None = None,
    points: int = CURVE_POINTS,
) -> Figure:
    """For each obliquity of the shots, a column: exit speed and exit obliquity against
    impact speed, the model's curves (``simulation`` on ``points`` speeds over the shots'
    speeds and a tenth of their span either side, for the report's sphere), its outcome
    bands as a strip, and the shots as markers by measured outcome (red edge: the model
    disagrees). Shots are drawn where they measured a value; every shot is drawn on the
    strip. A panel holds the shots of one obliquity to the nearest degree, and the
    model's curves at that degree; ShotDataError for more than MAX_PANELS panels.
    """
    shots = report.shots
    check_panels(shots)
    panels = panel_obliquities(shots)
    groups = np.unique(panels)
    # The shots' speeds and a tenth of their span either side (within the speeds searched).
    low, high = float(shots.impact_speed.min()), float(shots.impact_speed.max())
    pad = 0.1 * (high - low) or 0.1 * high
    span = (max(low - pad, report.speeds[0]), min(high + pad, report.speeds[1]))
    speeds = np.linspace(*span, points)
    model = simulation.run_batch(SceneBatch.grid(report.sphere, report.plate, speeds, groups))
    nrows = math.ceil(groups.size / MAX_COLUMNS)
    ncols = math.ceil(groups.size / nrows)
    fig = Figure(figsize=(PAGE_WIDTH, nrows * 3.0 + 0.8), layout="constrained")
    grid = fig.add_gridspec(3 * nrows, ncols, height_ratios=[1.1, 1.1, 0.2] * nrows)
    classes = np.array(measured_classes(shots))
    regimes = set()
    for n, obliquity in enumerate(groups):
        row, column = divmod(n, ncols)
        speed_ax = fig.add_subplot(grid[3 * row, column])
        angle_ax = fig.add_subplot(grid[3 * row + 1, column], sharex=speed_ax)
        strip_ax = fig.add_subplot(grid[3 * row + 2, column], sharex=speed_ax)
        part = model.take(np.arange(n * points, (n + 1) * points))
        plot_exit_curves([speed_ax, angle_ax], speeds, part, color="0.2", lw=1.0)
        regimes |= plot_outcome_strip(strip_ax, speeds, [("model", part)])
        mine = panels == obliquity
        for name, marker in MARKERS.items():
            for agrees in (True, False):
                index = mine & (classes == name) & (report.agrees == agrees)
                style: dict[str, Any] = {"marker": marker, "ls": "none", "ms": 4, "mfc": "white"}
                style["mec"] = AGREES if agrees else DISAGREES
                v = shots.impact_speed[index]
                speed_ax.plot(v, shots.residual_speed[index], **style)
                angle_ax.plot(v, np.degrees(shots.exit_obliquity[index]), **style)
                strip_ax.plot(v, np.zeros(v.size), **style)
        speed_ax.set_title(f"{math.degrees(obliquity):.6g}°", fontsize=FONT, pad=3)
        strip_ax.set_yticks([])
        strip_ax.set_xlim(*span)
        angle_ax.set_ylim(-8, 188)
        angle_ax.set_yticks([0, 45, 90, 135, 180])
        if column == 0:
            speed_ax.set_ylabel("exit speed [m/s]", fontsize=FONT)
            angle_ax.set_ylabel("exit obliquity [deg]", fontsize=FONT)
        if n + ncols >= groups.size:
            strip_ax.set_xlabel("impact speed [m/s]", fontsize=FONT)
        for ax in (speed_ax, angle_ax, strip_ax):
            ax.tick_params(labelsize=SMALL, length=2.5, width=0.6, pad=2)
        for ax in (speed_ax, angle_ax):
            ax.tick_params(labelbottom=False)
    entries = _key(set(classes)) + regime_key(regimes)
    fig.legend(handles=entries, loc="outside lower center", fontsize=SMALL, frameon=False,
               ncol=math.ceil(len(entries) / 3))  # fmt: skip
    agreement = f"outcome agreement {100 * report.agreement:.1f}% over {len(shots)} shots"
    drawn = simulation.model  # which model the curves and strips are (a plate, many models)
    names = f"{drawn.resistance.name} + {drawn.failure.name}, {simulation.integrator.name}"
    fig.suptitle(f"{title or report.plate.material}: {agreement}\nmodel: {names}",
                 fontsize=FONT + 1)  # fmt: skip
    return fig


def _key(classes: set[str]) -> list[Line2D]:
    """Legend handles: the model's curves, each measured outcome present, a disagreement."""
    handles = [Line2D([], [], color="0.2", lw=1.0, label="model")]
    for name, marker in MARKERS.items():
        if name in classes:
            label = f"go/no-go: {name}" if name in MEASURED[3:] else f"measured {name}"
            handles.append(Line2D([], [], marker=marker, ls="none", mfc="white", mec=AGREES,
                                  label=label))  # fmt: skip
    handles.append(Line2D([], [], marker="o", ls="none", mfc="white", mec=DISAGREES,
                          label="model disagrees"))  # fmt: skip
    return handles
