"""A crater section (the report's Figures 35-37): the crater floor, depth downward, with
the centre's path and the sphere at first contact, deepest and last."""

from __future__ import annotations

from typing import Any

import numpy as np
from matplotlib.axes import Axes

from ..model.results import CraterSection, Trajectory


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
    and ``radius``, the centre's path (dotted) and the sphere at first contact, deepest
    and last (thin circles). Every mark is labelled for a key (``ax.legend()``); the
    floor is "crater floor" unless ``label`` names it."""
    ax.plot(section.lateral * 1e3, section.depth * 1e3, label=label or "crater floor", **style)
    ax.axhline(0.0, color="0.3", lw=0.8, label="front surface")
    if trajectory is not None and radius is not None:
        shift = section.impact_point
        centre_y = (trajectory.lateral + shift) * 1e3
        centre_x = (trajectory.penetration - radius) * 1e3
        ax.plot(centre_y, centre_x, ls=":", color="0.35", lw=0.9, label="path of the centre")
        angles = np.linspace(0, 2 * np.pi, 181)
        for k, i in enumerate((0, int(np.argmax(trajectory.penetration)), -1)):
            ax.plot(
                centre_y[i] + radius * 1e3 * np.cos(angles),
                centre_x[i] + radius * 1e3 * np.sin(angles),
                color="0.45",
                lw=0.6,
                label="sphere at first contact, deepest, last" if k == 0 else "_nolegend_",
            )
    ax.set_xlabel("along the plate from entry [mm]")
    ax.set_ylabel("depth [mm]")
    ax.set_aspect("equal")
    if not ax.yaxis_inverted():
        ax.invert_yaxis()
    return ax
