"""The gallery's reading order: from a first look at the objects to writing a plug-in.
A script not listed comes after these, by file name."""

from __future__ import annotations

ORDER = [
    "notebook_objects.py",
    "report_figures_30_31.py",
    "limits_and_outcome_map.py",
    "validate_and_v50.py",
    "study_in_xarray.py",
    "third_party_plugin.py",
]


class ReadingOrder:
    """A sphinx-gallery sort key (``within_subsection_order``)."""

    def __init__(self, src_dir: str) -> None:
        self.src_dir = src_dir

    def __call__(self, filename: str) -> tuple[int, str]:
        return (ORDER.index(filename) if filename in ORDER else len(ORDER), filename)

    def __repr__(self) -> str:  # sphinx-gallery compares configurations by repr
        return f"<{type(self).__name__}: {', '.join(ORDER)}>"
