"""What ``show`` prints about a run: every input (the model's plug-ins and settings, the
scenes' spheres, plates and impacts) and its provenance (versions, source commit)."""

from __future__ import annotations

from typing import Any

import numpy as np

from ..batch import CORE_COLUMNS, SceneBatch
from ..errors import UnknownNameError
from ..parameters import Parameter
from ..registry import KINDS, default_registry

#: Distinct values of a scene column listed one by one; more are shown as a range.
LISTED_VALUES = 6


def _value(declared: Parameter | None, value: object) -> str:
    """A value [SI] in the user's unit, with the unit."""
    if declared is None:
        return str(value)
    unit = "" if declared.user_unit == "1" or value is None else f" {declared.user_unit}"
    return f"{declared.format(value)}{unit}"


def _plugin(kind: str, model: dict[str, Any]) -> str:
    """``dopri5 1 (rtol 1e-09, ...)``: name, version and every setting."""
    try:
        declarations = default_registry().get(kind, model[kind]).setting_declarations()
    except UnknownNameError:  # not installed here: the settings as stored [SI]
        declarations = {}
    settings = ", ".join(
        f"{name} {_value(declarations.get(name), value)}"
        for name, value in model.get(f"{kind}_settings", {}).items()
    )
    return f"{model[kind]} {model.get(f'{kind}_version', '?')} ({settings or 'no settings'})"


def run_lines(meta: dict[str, Any]) -> list[str]:
    """The model, commit and versions of an archived run (its metadata)."""
    model = meta["model"]
    lines = [f"  {kind}: {_plugin(kind, model)}" for kind in KINDS]
    lines.append(f"  rest_speed_fraction: {model.get('rest_speed_fraction')}")
    versions = ", ".join(f"{name} {version}" for name, version in meta["versions"].items())
    lines.append(f"  source commit {meta['git_commit']}; {versions}")
    return lines


def scene_line(scenes: SceneBatch, plate_labels: tuple[str, ...]) -> str:
    """Each scene column: its one value, its few values, or its range [user units]."""
    declared = {**CORE_COLUMNS, **default_registry().plate_constants}
    columns = scenes.columns
    parts = [f"plates {', '.join(dict.fromkeys(plate_labels))}"]
    for name in sorted(columns, key=lambda n: (n not in CORE_COLUMNS, n)):
        distinct = [_value(declared.get(name), float(x)) for x in np.unique(columns[name])]
        if len(distinct) > LISTED_VALUES:
            distinct = [f"{distinct[0]} to {distinct[-1]} ({len(distinct)} values)"]
        parts.append(f"{name} {', '.join(distinct)}")
    return "  scenes: " + "; ".join(parts)
