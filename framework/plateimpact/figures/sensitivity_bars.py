"""The bar chart of Sobol' indices: each input's first-order and total index, with their
confidence intervals, at journal column width."""

from __future__ import annotations

import numpy as np
from matplotlib.figure import Figure

from ..uncertainty.sensitivity import SobolIndices
from . import style


def plot_sobol_indices(found: SobolIndices, title: str) -> Figure:
    """First-order (S1) and total (ST) indices of each input, intervals as error bars."""
    fig, ax = style.figure(figsize=(style.COLUMN_WIDTH, 2.4), layout="constrained")
    x = np.arange(len(found.names))
    width = 0.38
    ax.bar(x - width / 2, found.first, width, yerr=found.first_halfwidth, capsize=2,
           label="first order S1", color="0.35")  # fmt: skip
    ax.bar(x + width / 2, found.total, width, yerr=found.total_halfwidth, capsize=2,
           label="total ST", color="0.75", edgecolor="0.2", linewidth=0.5)  # fmt: skip
    ax.set_xticks(x, found.names, fontsize=style.SMALL)
    ax.set_ylabel("Sobol' index", fontsize=style.FONT)
    ax.set_ylim(min(0.0, float(np.min(found.first - found.first_halfwidth))) - 0.02, 1.05)
    ax.axhline(0.0, color="0.5", linewidth=0.5)
    ax.tick_params(labelsize=style.SMALL)
    ax.legend(fontsize=style.SMALL, frameon=False)
    level = round(100 * found.confidence)
    ax.set_title(
        f"{title}\n{found.evaluations:,} runs; bars: {level}% bootstrap intervals",
        fontsize=style.SMALL,
    )
    return fig
