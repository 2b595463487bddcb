"""What ``show`` prints about a run: every input (the model's plug-ins and settings, the
scenes' spheres, plates and impacts) and its provenance (versions, source commit).

Everything here comes from an archive, which may come from anyone: every piece of its
text (names, labels, hosts, settings) goes through :func:`untrusted.printable` before it
is printed, so that a new line, an escape sequence or a bidirectional override in it
prints inert, and a value of the wrong type prints as what it is instead of failing.
"""

from __future__ import annotations

import math
from typing import Any

import numpy as np

from ..model.batch import CORE_COLUMNS, SceneBatch
from ..model.results import BatchResult
from ..registry.described import plugin_line, stored_value
from ..registry.plugin_registry import KINDS, PluginRegistry
from ..storage.archive import Archive
from .formatting import LONGEST_TEXT, shown

__all__ = ["LONGEST_TEXT", "run_description", "run_lines", "scene_line", "seconds", "shown"]

#: Distinct values of a scene column listed one by one; more are shown as a range.
LISTED_VALUES = 6


def seconds(value: object) -> str:
    """A duration [s] as ``0.42 s``, or what the archive holds instead of a number."""
    if isinstance(value, int | float) and not isinstance(value, bool) and math.isfinite(value):
        return f"{value:.2f} s"
    return shown(value)


def run_lines(meta: dict[str, Any], registry: PluginRegistry) -> list[str]:
    """The model, commit and versions of an archived run (its metadata)."""
    model = meta.get("model")
    model = model if isinstance(model, dict) else {}
    lines = [f"  {kind}: {plugin_line(kind, model, registry)}" for kind in KINDS]
    lines.append(f"  rest_speed_fraction: {shown(model.get('rest_speed_fraction'))}")
    found = meta.get("versions")
    versions = ", ".join(
        f"{shown(name)} {shown(version)}"
        for name, version in (found.items() if isinstance(found, dict) else [])
    )
    lines.append(f"  source commit {shown(meta.get('git_commit'))}; {versions}")
    return lines


def scene_line(scenes: SceneBatch, plate_labels: tuple[str, ...], registry: PluginRegistry) -> str:
    """Each scene column: its one value, its few values, or its range [user units]."""
    declared = {**CORE_COLUMNS, **registry.plate_constants}
    columns = scenes.columns
    parts = [f"plates {', '.join(shown(label) for label in dict.fromkeys(plate_labels))}"]
    for name in sorted(columns, key=lambda n: (n not in CORE_COLUMNS, n)):
        distinct = [stored_value(declared.get(name), float(x)) for x in np.unique(columns[name])]
        if len(distinct) > LISTED_VALUES:
            distinct = [f"{distinct[0]} to {distinct[-1]} ({len(distinct)} values)"]
        parts.append(f"{shown(name)} {', '.join(distinct)}")
    return "  scenes: " + "; ".join(parts)


def run_description(archive: Archive, name: str, registry: PluginRegistry) -> list[str]:
    """What ``show`` prints of the run ``name`` (STUDY/RUN), settings and scene columns
    as the plug-ins of ``registry`` declare them."""
    meta: dict[str, Any] = archive.metadata(name)
    result: BatchResult = archive.results(name)
    counts = np.bincount(result.outcome, minlength=4)[1:]
    from ..provenance.code import summary  # noqa: PLC0415 (hashing only here)

    lines = [shown(name, None), *run_lines(meta, registry)]
    # each plug-in's origin and source hash (printable already)
    lines += [f"  {line}" for line in summary(meta.get("plugins"))]
    study = archive.study(name.split("/", 1)[0])
    lines.append(scene_line(study.scenes, study.plate_labels, registry))
    lines.append(
        f"  {len(result)} scenes: {counts[0]} ricochet, {counts[1]} embedment, "
        f"{counts[2]} perforation; wall {seconds(meta.get('wall_time_s'))}"
    )
    kept = [
        what
        for what, data in (("trajectories", result.trajectory), ("craters", result.craters))
        if data is not None
    ]
    if kept:
        lines.append(f"  with {' and '.join(kept)}")
    lines.append(f"  run {shown(meta.get('start_time'))} on {shown(meta.get('host'))}")
    data = archive.data_file(name)  # format 2: the run's own netCDF file
    lines.append(f"  data {shown(data, None)}" if data else "  data in the archive (format 1)")
    return lines
