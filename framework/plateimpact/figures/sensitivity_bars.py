"""The bar chart of Sobol' indices: each input's first-order and total index, with their
confidence intervals, one panel per quantity (whether a sample perforates, the ballistic
limit): a column wide for one, the page for two."""

from __future__ import annotations

from collections.abc import Mapping

import numpy as np
from matplotlib.figure import Figure

from ..uncertainty.sensitivity import SobolIndices
from . import style

#: How a panel names each quantity.
QUANTITIES = {"perforation": "P(perforation)", "ballistic_limit": "ballistic limit"}


def plot_sobol_indices(
    found: Mapping[str, SobolIndices], title: str, provenance: str | None = None
) -> Figure:
    """First-order (S1) and total (ST) indices of each input, intervals as error bars, a
    panel per quantity of ``found`` (by its key: :data:`QUANTITIES`); ``provenance`` in
    small print at the foot."""
    width = style.COLUMN_WIDTH if len(found) == 1 else style.PAGE_WIDTH
    fig, axes = style.figure(1, len(found), figsize=(width, 2.6), layout="constrained",
                             squeeze=False)  # fmt: skip
    for ax, (quantity, indices) in zip(axes[0], found.items(), strict=True):
        x = np.arange(len(indices.names))
        bar = 0.38
        ax.bar(x - bar / 2, indices.first, bar, yerr=indices.first_halfwidth, capsize=2,
               label="first order S1", color="0.35")  # fmt: skip
        ax.bar(x + bar / 2, indices.total, bar, yerr=indices.total_halfwidth, capsize=2,
               label="total ST", color="0.75", edgecolor="0.2", linewidth=0.5)  # fmt: skip
        ax.set_xticks(x, indices.names, fontsize=style.SMALL)
        ax.set_ylabel("Sobol' index", fontsize=style.FONT)
        low = float(np.min(indices.first - indices.first_halfwidth))
        ax.set_ylim(min(0.0, low) - 0.02, 1.05)
        ax.axhline(0.0, color="0.5", linewidth=0.5)
        ax.tick_params(labelsize=style.SMALL)
        ax.legend(fontsize=style.SMALL, frameon=False)
        level = round(100 * indices.confidence)
        ax.set_title(
            f"{title}: {QUANTITIES.get(quantity, quantity)}\n{indices.evaluations:,} "
            f"evaluations; bars: {level}% bootstrap intervals",
            fontsize=style.SMALL,
        )
    if provenance:
        style.small_print(fig, provenance, width)
    return fig
