"""The probabilistic velocity-response curve of an uncertainty study: P(perforation | V)
read off the sampled ballistic limits (and P(ricochet | V) off the ricochet limits),
each with its exact binomial band and V10/V50/V90 marked, one panel per obliquity,
optionally beside go/no-go shots and their V50 fit (figures.v50_fits draws those), so
that the model and the firings are on the same axes (matplotlib is imported only here)."""

from __future__ import annotations

import math
from collections.abc import Mapping, Sequence

import attrs
import numpy as np
from matplotlib.axes import Axes
from matplotlib.figure import Figure

from ..limits.regimes import REGIMES
from ..uncertainty.limits import LEVELS, SampledLimits
from ..v50.fit import V50Fit
from .style import FONT, PAGE_WIDTH, REGIME_COLOURS, SMALL, panel_grid, shared_key, small_print
from .v50_fits import draw_fit, draw_shots, probability_axes

#: Speeds at which a curve is evaluated (a step function: as many as a panel has pixels).
CURVE_POINTS = 600
#: The model's curves: perforation, ricochet (the regime palette's), and the shots' fit.
PERFORATION_COLOUR, RICOCHET_COLOUR = REGIME_COLOURS[REGIMES[4]], REGIME_COLOURS[REGIMES[0]]
SHOTS_FIT_COLOUR = "k"


@attrs.frozen(eq=False)
class ShotGroup:
    """Go/no-go shots at one obliquity: speeds [m/s], whether each perforated, weights,
    and their V50 fit (or why there is none)."""

    speed: np.ndarray
    perforated: np.ndarray
    weight: np.ndarray
    fit: V50Fit | str


def _span(found: SampledLimits, shots: ShotGroup | None) -> tuple[float, float]:
    """The speeds drawn [m/s]: the middle 98% of the finite limits of both kinds, the
    shots, and a tenth of that either side, inside the range searched."""
    values = [v[np.isfinite(v)] for v in (found.ballistic, found.ricochet)]
    finite = np.concatenate(values)
    points = list(np.quantile(finite, [0.01, 0.99])) if finite.size else list(found.speeds)
    if shots is not None:
        points += [float(shots.speed.min()), float(shots.speed.max())]
    low, high = min(points), max(points)
    pad = 0.1 * (high - low) or 0.05 * high
    return max(low - pad, found.speeds[0]), min(high + pad, found.speeds[1])


def _curve(ax: Axes, speeds: np.ndarray, curve: tuple, colour: str, label: str, ls: str) -> None:
    probability, low, high = curve
    ax.fill_between(speeds, low, high, step="post", color=colour, alpha=0.25, lw=0)
    ax.step(speeds, probability, where="post", color=colour, lw=1.2, ls=ls, label=label)


def _draw(ax: Axes, found: SampledLimits, shots: ShotGroup | None, confidence: float) -> None:
    low, high = _span(found, shots)
    speeds = np.linspace(low, high, CURVE_POINTS)
    level = f"{100 * confidence:g}%"
    _curve(ax, speeds, found.perforation_curve(speeds, confidence), PERFORATION_COLOUR,
           f"model P(perforation | V), {level} band", "-")  # fmt: skip
    if np.any(found.ricochet > low):  # some sample ricochets in the speeds drawn
        _curve(ax, speeds, found.ricochet_curve(speeds, confidence), RICOCHET_COLOUR,
               f"model P(ricochet | V), {level} band", "--")  # fmt: skip
    marks = {}
    for key, level_p in LEVELS.items():
        at = found.quantile(level_p, confidence)["speed_m_s"]
        if low <= at <= high:
            ax.axvline(at, color=PERFORATION_COLOUR, lw=0.6, ls=":")
            ax.text(at, 1.09, key.upper(), fontsize=SMALL - 1, ha="center", va="bottom",
                    color=PERFORATION_COLOUR)  # fmt: skip
        side = f"below {found.speeds[0]:g}" if at < 0 else f"beyond {found.speeds[1]:g}"
        marks[key] = f"{at:.4g}" if math.isfinite(at) else side
    title = (
        f"{math.degrees(found.obliquity):.4g} deg\nmodel V50 {marks['v50']} m/s "
        f"(V10 {marks['v10']}, V90 {marks['v90']})"
    )
    if shots is not None:
        if isinstance(shots.fit, V50Fit):
            draw_fit(ax, shots.fit, low, high, SHOTS_FIT_COLOUR, "shots' ")
            title += f"\nshots: {shots.fit.method} V50 {shots.fit.v50_m_s:.4g} m/s"
        else:
            title += "\nshots: no V50 fit"
        draw_shots(ax, shots.speed, shots.perforated, shots.weight, np.random.default_rng(0))
    probability_axes(ax, (low, high), 1.16, "probability")
    ax.set_title(title, fontsize=SMALL)


def plot_velocity_response(
    found: Sequence[SampledLimits],
    shots: Mapping[int, ShotGroup] | None = None,
    *,
    title: str,
    provenance: str,
    confidence: float = 0.95,
) -> Figure:
    """P(perforation | V) (solid) and P(ricochet | V) (dashed) from the sampled limits at
    each obliquity (one panel each, page width), with their exact ``confidence`` bands and
    V10/V50/V90 marked; ``shots[k]``: the shots at obliquity ``k`` of ``found`` and their
    fit, drawn on the same axes; ``provenance`` in small print at the foot."""
    shots = shots or {}
    fig, axes = panel_grid(len(found), PAGE_WIDTH, 2.7, 0.9, columns=3)  # the page
    for k, (ax, one) in enumerate(zip(axes, found, strict=False)):
        _draw(ax, one, shots.get(k), confidence)
    shared_key(fig, axes, len(found))
    fig.suptitle(title, fontsize=FONT)
    small_print(fig, provenance, PAGE_WIDTH)
    return fig
