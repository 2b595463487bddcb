"""Sphinx configuration of the plateimpact documentation site.

Build (README, "Documentation"): ``pip install ".[docs]"`` then
``sphinx-build -W --keep-going -n -b html docs docs/_build/html``. The Markdown pages are
read by myst-parser, the API reference (``api/``) is generated from the docstrings by
autodoc and autosummary (numpydoc sections), and the gallery is the scripts of
``examples/``, run by sphinx-gallery at every build so that none can drift from the code.
"""

from __future__ import annotations

import os
import sys
from pathlib import Path

import plateimpact

HERE = Path(__file__).resolve().parent
sys.path.insert(0, str(HERE))  # _ext: the resolver of our own short names below

# Gallery scripts and anything else the build runs: the numpy path (no compilation on
# the build machine), and a cache of compiled programs that cannot touch the user's.
os.environ.setdefault("PLATEIMPACT_COMPILE", "off")
os.environ.setdefault("MPLBACKEND", "Agg")

project = "plateimpact"
author = "the plateimpact developers"
copyright = "2026, the plateimpact developers"  # noqa: A001 (Sphinx's name)
release = plateimpact.__version__
version = release

extensions = [
    "sphinx.ext.autodoc",
    "sphinx.ext.autosummary",
    "sphinx.ext.mathjax",
    "numpydoc",
    "myst_parser",
    "sphinx_gallery.gen_gallery",
    "_ext.public_names",
]

source_suffix = {".rst": "restructuredtext", ".md": "markdown"}
root_doc = "index"
exclude_patterns = ["_build", "examples/**", "gallery/*.ipynb", "gallery/*.py", "**/*.zip"]
templates_path = ["_templates"]

# -- Markdown pages ---------------------------------------------------------------------
# Anchors for the pages' headings, so that ``archive.md#figures`` resolves.
myst_heading_anchors = 3
myst_enable_extensions = ["dollarmath"]

# -- API reference ----------------------------------------------------------------------
autosummary_generate = True
autosummary_imported_members = True
autodoc_default_options = {"members": True}
autodoc_member_order = "bysource"
# Signatures show the names of the arguments; their units and meaning are in the
# docstrings, in brackets ([m], [rad]). The annotations stay in the source, for mypy.
autodoc_typehints = "none"
autodoc_preserve_defaults = True
autoclass_content = "both"
numpydoc_show_class_members = False
numpydoc_class_members_toctree = False
numpydoc_xref_param_type = False

# -- Gallery ----------------------------------------------------------------------------
sphinx_gallery_conf = {
    "examples_dirs": "examples",
    "gallery_dirs": "gallery",
    "filename_pattern": r".*\.py$",  # every script runs at build time
    "ignore_pattern": r"(__init__|_common)\.py$",
    "download_all_examples": False,
    "remove_config_comments": True,
    "within_subsection_order": "FileNameSortKey",
    "image_scrapers": ("matplotlib",),
    "capture_repr": ("_repr_html_", "__repr__"),
    "abort_on_example_error": False,
    "only_warn_on_example_error": False,
    "show_memory": False,
    "plot_gallery": "True",
}

# -- Cross-references -------------------------------------------------------------------
# Nitpicky builds (-n) require every reference to resolve. Ours resolve to the public
# names (_ext/public_names.py maps a module path or a short name to ``plateimpact.X``).
# The build has no network (CI reaches package registries only), so no intersphinx
# inventory can be fetched: references to other projects' types stay plain text, and
# are listed here by package, never one of ours.
nitpick_ignore_regex = [
    ("py:.*", r"(numpy|np|numpy\.typing|npt|xarray|xr|pandas|pd|matplotlib|scipy)(\..*)?"),
    ("py:.*", r"(typing|collections\.abc|collections|pathlib|os|io|enum|concurrent)(\..*)?"),
    ("py:.*", r"(attrs|attr|pluggy|h5py|h5netcdf|numba|dask|distributed|SALib|tqdm)(\..*)?"),
    ("py:.*", r"(float|int|str|bool|bytes|object|dict|list|tuple|set|type|None|callable)"),
    ("py:.*", r"(Exception|ValueError|TypeError|KeyError|Warning|UserWarning|OSError)"),
    ("py:.*", r"(DeprecationWarning|RuntimeError|LookupError|FileNotFoundError)"),
]

# -- HTML -------------------------------------------------------------------------------
html_theme = "pydata_sphinx_theme"
html_title = f"plateimpact {release}"
html_theme_options = {
    "navigation_with_keys": False,
    "show_toc_level": 2,
}
html_static_path: list[str] = []
html_show_sourcelink = False
