"""A model's plug-ins as people read them: each slot's name, version and settings in the
units the plug-in declares (``dopri5 1 (rtol 1e-09, ...)``), from a model's record
(:meth:`~plateimpact.Simulation.describe`, an archive's, a limits record's). The record
may come from someone else's file: every piece of its text is printed inert
(:func:`~plateimpact.base.untrusted.printable`), and a value the declaration cannot
describe is shown as it is stored."""

from __future__ import annotations

import json
from typing import Any

from ..base.parameters import Parameter
from ..base.untrusted import printable
from .plugin_registry import PluginRegistry

#: Longest piece of a record's text shown [characters] (a longer one is cut, "...").
LONGEST_TEXT = 200


def shown(value: object) -> str:
    return printable(value, LONGEST_TEXT)


def stored_value(declared: Parameter | None, value: object) -> str:
    """A value [SI] in the user's unit, with the unit; a value the declaration cannot
    describe (an archive's, of another version of the plug-in) as it is stored."""
    if declared is None:
        return shown(json.dumps(value) if not isinstance(value, str) else value)
    unit = "" if declared.user_unit == "1" or value is None else f" {declared.user_unit}"
    try:
        return f"{shown(declared.format(value))}{unit}"
    except Exception:  # a plug-in's own formatting of a stored value: show the value
        return shown(json.dumps(value, default=str))


def plugin_line(kind: str, model: dict[str, Any], plugins: PluginRegistry | None) -> str:
    """``dopri5 1 (rtol 1e-09, ...)``: name, version and every setting (declared by
    ``plugins`` where it has the plug-in; otherwise as stored [SI])."""
    name = model.get(kind)
    declarations: dict[str, Parameter] = {}
    if plugins is not None and isinstance(name, str) and name in plugins.names(kind):
        declarations = plugins.get(kind, name).setting_declarations()
    stored = model.get(f"{kind}_settings")
    settings = ", ".join(
        f"{shown(setting)} {stored_value(declarations.get(setting), value)}"
        for setting, value in (stored.items() if isinstance(stored, dict) else [])
    )
    version = shown(model.get(f"{kind}_version", "?"))
    return f"{shown(name)} {version} ({settings or 'no settings'})"
