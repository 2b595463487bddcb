"""A sphinx-gallery image scraper for figures made outside pyplot.

plateimpact draws every figure as a :class:`matplotlib.figure.Figure` of its own
(``plateimpact.figures.style``: nothing touches pyplot's state), which the matplotlib
scraper, reading pyplot's open figures, never sees. This one looks for Figure objects
among a gallery script's variables after each cell and saves each new one once, as
sphinx-gallery saves pyplot's (a notebook shows the same figure when the cell ends with
it).
"""

from __future__ import annotations

from typing import Any

from matplotlib.figure import Figure
from sphinx_gallery.scrapers import figure_rst

#: The figures already shown, per script (the objects, not their ids, which are reused).
_SHOWN: dict[str, list[Figure]] = {}


def figures_in_namespace(block: Any, block_vars: dict[str, Any], gallery_conf: dict) -> str:
    shown = _SHOWN.setdefault(str(block_vars["src_file"]), [])
    new: list[Figure] = []
    for value in block_vars["example_globals"].values():  # "___" too: the cell's value
        if isinstance(value, Figure) and not any(value is old for old in [*shown, *new]):
            new.append(value)
    paths = []
    for figure, path in zip(new, block_vars["image_path_iterator"], strict=False):
        figure.savefig(path)
        shown.append(figure)
        paths.append(path)
    return figure_rst(paths, gallery_conf["src_dir"])
