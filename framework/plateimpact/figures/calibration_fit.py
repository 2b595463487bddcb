"""A calibration in the layout of the report's Figure 11: residual speed against impact
speed, the shots, the DRI fit and the model's curves."""

from __future__ import annotations

from collections.abc import Mapping
from typing import TYPE_CHECKING

import numpy as np
from matplotlib.axes import Axes

if TYPE_CHECKING:
    from ..calibration import DriFit
    from ..storage.shots import Shots


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
