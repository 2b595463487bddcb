"""The figure of V50 statistics: P(perforation) against impact speed, one panel per group
of shots (matplotlib is imported only here)."""

from __future__ import annotations

import textwrap
from collections.abc import Sequence

import attrs
import numpy as np
from matplotlib.axes import Axes
from matplotlib.figure import Figure

from ..v50.fit import V50Fit
from ..v50.mil_std import MilStd662F
from .style import FONT, SMALL, panel_grid, shared_key

#: Points of the fitted curve; shots are drawn this far off 0 and 1 at most (jitter, so
#: that shots at one speed stay apart), seeded so the figure is the same each time.
CURVE_POINTS, JITTER = 300, 0.04
#: Colours: the fit, its V50 interval, the model's ballistic limit.
FIT_COLOUR, BAND_COLOUR, MODEL_COLOUR = "k", "#9ecae1", "#d62728"


@attrs.frozen(eq=False)
class Panel:
    """One group of shots (speeds [m/s], perforated, weights), its estimate (or why there
    is none) and the model's ballistic limit [m/s] at its obliquity (None: not asked, or
    none found)."""

    title: str
    speed: np.ndarray
    perforated: np.ndarray
    weight: np.ndarray
    estimate: V50Fit | MilStd662F | str
    model_ballistic_limit: float | None = None


def _span(panel: Panel) -> tuple[float, float]:
    """The speeds drawn [m/s]: the shots', the V50 interval's and the model's limit, and a
    tenth of that span either side."""
    values = list(panel.speed)
    if isinstance(panel.estimate, V50Fit):
        values += [x for x in (*panel.estimate.v50_ci_m_s, panel.estimate.v10_m_s,
                               panel.estimate.v90_m_s) if x is not None]  # fmt: skip
    if panel.model_ballistic_limit is not None:
        values.append(panel.model_ballistic_limit)
    low, high = min(values), max(values)
    pad = 0.1 * (high - low) or 0.05 * high
    return low - pad, high + pad


def draw_fit(
    ax: Axes, estimate: V50Fit, low: float, high: float, colour: str = FIT_COLOUR,
    what: str = "",
) -> None:  # fmt: skip
    """The fitted curve over [``low``, ``high``] [m/s], its V50 marked and the V50's
    profile interval shaded; ``what`` goes before the legend's labels (whose fit)."""
    ci_low, ci_high = estimate.v50_ci_m_s
    ax.axvspan(low if ci_low is None else ci_low, high if ci_high is None else ci_high,
               color=BAND_COLOUR, alpha=0.5, lw=0,
               label=f"{what}V50 {100 * estimate.confidence:g}% interval (profile)")  # fmt: skip
    speeds = np.linspace(low, high, CURVE_POINTS)
    ax.plot(speeds, estimate.probability(speeds), color=colour, lw=1.2,
            label=f"{what}{estimate.method} fit")  # fmt: skip
    ax.axvline(estimate.v50_m_s, color=colour, lw=0.6, ls=":", label=f"{what}V50")


def draw_shots(
    ax: Axes, speed: np.ndarray, perforated: np.ndarray, weight: np.ndarray,
    rng: np.random.Generator,
) -> None:  # fmt: skip
    """Each shot of positive weight at 0 or 1 (jittered a little inward, so that shots at
    one speed stay apart): triangles perforated, circles not."""
    shown = weight > 0
    y = perforated.astype(float)
    jitter = rng.uniform(0.0, JITTER, y.size) * np.where(perforated, -1.0, 1.0)
    for kind, marker, label in ((True, "^", "perforated"), (False, "o", "not perforated")):
        mask = shown & (perforated == kind)
        ax.plot(speed[mask], (y + jitter)[mask], marker, ms=3.5, mfc="none", mec="k",
                ls="none", label=label)  # fmt: skip


def _draw(ax: Axes, panel: Panel, rng: np.random.Generator) -> None:
    low, high = _span(panel)
    estimate = panel.estimate
    if isinstance(estimate, V50Fit):
        draw_fit(ax, estimate, low, high)
        title = (f"{panel.title}: V50 {estimate.v50_m_s:.4g} m/s, "
                 f"σ {estimate.sigma_m_s:.3g} m/s")  # fmt: skip
    elif isinstance(estimate, MilStd662F):
        used = np.asarray(estimate.used)
        ax.axvspan(
            float(panel.speed[used].min()),
            float(panel.speed[used].max()),
            color=BAND_COLOUR,
            alpha=0.5,
            lw=0,
            label="span of the rounds averaged",
        )
        ax.axvline(estimate.v50_m_s, color=FIT_COLOUR, lw=1.2, label="MIL-STD-662F V50")
        title = (f"{panel.title}: V50 {estimate.v50_m_s:.4g} m/s "
                 f"({estimate.rounds} rounds)")  # fmt: skip
    else:
        ax.text(0.5, 0.5, "\n".join(textwrap.wrap(estimate, 34)), transform=ax.transAxes,
                ha="center", va="center", fontsize=SMALL)  # fmt: skip
        title = f"{panel.title}: no V50"
    if panel.model_ballistic_limit is not None:
        ax.axvline(panel.model_ballistic_limit, color=MODEL_COLOUR, lw=1.0, ls="--",
                   label="model's ballistic limit")  # fmt: skip
        title += f"\nmodel's ballistic limit {panel.model_ballistic_limit:.4g} m/s"
    draw_shots(ax, panel.speed, panel.perforated, panel.weight, rng)
    probability_axes(ax, (low, high), 1.08, "P(perforation)")
    ax.set_title(title, fontsize=FONT)


def probability_axes(ax: Axes, speeds: tuple[float, float], top: float, label: str) -> None:
    """A probability against impact speed [m/s] over ``speeds``: from a little below 0 to
    ``top`` (room above 1 for the shots and marks), labelled ``label``."""
    ax.set_xlim(*speeds)
    ax.set_ylim(-0.08, top)
    ax.set_xlabel("impact speed [m/s]", fontsize=FONT)
    ax.set_ylabel(label, fontsize=FONT)
    ax.tick_params(labelsize=SMALL)


def v50_figure(panels: Sequence[Panel], *, title: str = "", model: str | None = None) -> Figure:
    """P(perforation) against impact speed, a panel per group: the shots at 0 and 1
    (jittered a little inward), the fitted curve with its V50 interval shaded (or the
    MIL-STD-662F V50 and the span of its rounds), and the model's ballistic limit dashed."""
    fig, axes = panel_grid(len(panels), 3.6, 2.8, 0.5)
    rng = np.random.default_rng(0)
    for ax, panel in zip(axes, panels, strict=False):
        _draw(ax, panel, rng)
    shared_key(fig, axes, len(panels))
    heading = f"{title}: probability of perforation" if title else "probability of perforation"
    if model:
        heading += f"; model {model}"
    fig.suptitle(heading, fontsize=FONT)
    return fig
