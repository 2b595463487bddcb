"""Crater sections and trajectories of a study's runs: :func:`plot_study_paths`, one panel
per plate × obliquity, drawn at journal width (matplotlib is imported here, only when
drawing)."""

from __future__ import annotations

from collections.abc import Sequence
from typing import TYPE_CHECKING

import matplotlib
import numpy as np
from matplotlib.figure import Figure

from ..model.results import Outcome
from .exit_curves import short_run_name, study_panels
from .style import FONT, PAGE_WIDTH, SMALL, figure

if TYPE_CHECKING:
    from ..study.study import StudyResults

#: What :func:`plot_study_paths` can draw from a run.
PATH_KINDS = ("trajectory", "crater")


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
    panels = study_panels(results)
    fig, axes = figure(
        len(panels), 1, figsize=(PAGE_WIDTH, 0.6 + 2.1 * len(panels)), squeeze=False,
        layout="constrained",
    )  # fmt: skip
    for ax, (label, ob, index) in zip(axes[:, 0], panels, strict=True):
        chosen = index[_pick(study.scenes.impact_speed[index], speeds, count)]
        # viridis short of its pale end: every line keeps a 3:1 contrast with white paper
        # (WCAG's threshold for graphics), which the yellow-green beyond 0.6 does not
        colours = matplotlib.colormaps["viridis"](np.linspace(0.0, 0.6, chosen.size))
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
        ax.axhline(0.0, color="0.3", lw=0.8, label="front surface")
        ax.axhline(thickness, color="0.3", lw=0.8, ls=":", label="back surface")
        ax.set_title(
            f"{label}, {ob:g}° ({', '.join(short_run_name(r, study.name) for r in runs)})",
            fontsize=FONT,
            pad=3,
        )
        ax.set_xlabel("along the plate [mm]", fontsize=FONT)
        ax.set_ylabel("depth [mm]" if kind == "crater" else "centre depth [mm]", fontsize=FONT)
        ax.tick_params(labelsize=SMALL, length=2.5, width=0.6, pad=2)
        ax.set_aspect("equal", adjustable="datalim")
        ax.invert_yaxis()
        ax.legend(fontsize=SMALL, loc="upper left", bbox_to_anchor=(1.01, 1.0), frameon=False)
    what = "crater sections" if kind == "crater" else "trajectories of the centre"
    plates = ", ".join(dict.fromkeys(study.plate_labels))
    fig.suptitle(f"{plates} (study {study.name}): {what}", fontsize=FONT + 1)
    return fig
