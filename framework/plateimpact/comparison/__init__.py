"""Two runs of a study compared scene by scene, the outcome changes collapsed into
ranges along impact speed (or obliquity) per plate (docs/archive.md, "Comparing runs").

>>> comparison = results.compare("plugging", "large-pstar")
>>> comparison.ranges()[0].pair, comparison.summary()["changes"]
>>> from plateimpact.figures.compared_runs import plot_comparison  # matplotlib: imported apart
"""

from __future__ import annotations

from .ranges import Comparison, ComparisonRow, OutcomeRange, Spread

__all__ = ["Comparison", "ComparisonRow", "OutcomeRange", "Spread"]
