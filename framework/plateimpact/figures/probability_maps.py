"""Probability maps of an uncertainty study over the (impact speed, obliquity) plane:
P(perforation) and P(ricochet) at each point of an outcome grid (uncertainty.curves),
as images with contours at 10, 50 and 90% and one colour bar (matplotlib only here)."""

from __future__ import annotations

from matplotlib.figure import Figure

from ..uncertainty.curves import OutcomeGrid
from .limits_and_maps import cell_edges
from .style import FONT, PAGE_WIDTH, SMALL, figure, small_print

#: The outcomes mapped, and the probabilities contoured.
MAPPED = ("perforation", "ricochet")
LEVELS = (0.1, 0.5, 0.9)


def plot_probability_maps(found: OutcomeGrid, *, title: str, provenance: str) -> Figure:
    """One panel per outcome of :data:`MAPPED`: its probability at each grid point as an
    image (each cell reaching half-way to its neighbours), contours at :data:`LEVELS`,
    speed [m/s] across and obliquity [deg] up; one colour bar; page width, with
    ``provenance`` in small print at the foot."""
    fig, axes = figure(1, len(MAPPED), figsize=(PAGE_WIDTH, 3.0), layout="constrained",
                       sharey=True)  # fmt: skip
    probabilities = found.probabilities()
    speeds, degrees = found.speeds_m_s, found.obliquities_deg
    images = []
    for ax, outcome in zip(axes, MAPPED, strict=True):
        values = probabilities[outcome].T  # rows: obliquities, columns: speeds
        image = ax.pcolormesh(cell_edges(speeds), cell_edges(degrees), values,
                              vmin=0.0, vmax=1.0, cmap="viridis")  # fmt: skip
        images.append(image)
        crossed = [p for p in LEVELS if values.min() < p < values.max()]
        if crossed:  # contours only where the probability crosses them
            lines = ax.contour(speeds, degrees, values, levels=crossed, colors="w",
                               linewidths=0.7)  # fmt: skip
            ax.clabel(lines, fontsize=SMALL - 1, fmt=lambda p: f"{p:.1f}")
        ax.set_title(f"P({outcome})", fontsize=FONT)
        ax.set_xlabel("impact speed [m/s]", fontsize=FONT)
        ax.tick_params(labelsize=SMALL)
    axes[0].set_ylabel("impact obliquity [deg]", fontsize=FONT)
    bar = fig.colorbar(images[0], ax=list(axes), shrink=0.9)
    bar.set_label("probability (fraction of the samples)", fontsize=FONT)
    bar.ax.tick_params(labelsize=SMALL)
    points = f"{speeds.size} x {degrees.size} points, {found.samples:,} samples at each"
    fig.suptitle(f"{title}: {points}", fontsize=FONT)
    small_print(fig, provenance, PAGE_WIDTH)
    return fig
