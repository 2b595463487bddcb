"""A batch bound to a model: the driver's columns and each plug-in's namespaced view."""

from __future__ import annotations

from collections.abc import Sequence
from typing import Any

import numpy as np

from ..base.errors import ParameterError, PluginError
from ..base.parameters import Parameter, Range
from .batch import CORE_COLUMNS, SceneBatch
from .plugin import Plugin

ONSET_PENETRATION = Parameter(
    "onset_penetration",
    "penetration at which the plate fails (the failure model's; inf: never)",
    "m",
    Range(0.0, low_open=True, allow_inf=True),
    "mm",
    1e-3,
)

#: The model's slots whose plug-ins get a view of the batch, in binding order.
SLOTS = ("resistance", "failure")


class BoundBatch:
    """The scenes as the step loop sees them.

    One flat set of arrays (core columns, plate constants, each plug-in's prepared
    columns under ``SLOT.NAME``, and the driver's ``onset_penetration`` [m] and
    ``rest_speed`` [m/s]) and three views of it that share those arrays:

    * ``core``: the core columns and the driver's two;
    * ``resistance`` and ``failure``: the core columns, the plate constants that plug-in
      declared and the columns it prepared, by their plain names.

    A plug-in therefore reads only what it declared, and two plug-ins' columns cannot
    collide. :meth:`take` subsets every array once and rebuilds the views.
    """

    __slots__ = ("_columns", "_keys", "core", "failure", "resistance", "size")

    def __init__(
        self, columns: dict[str, np.ndarray], keys: dict[str, dict[str, str]], size: int
    ) -> None:
        self._columns = columns
        self._keys = keys
        self.size = size
        self.core = self.view("core")
        self.resistance = self.view("resistance")
        self.failure = self.view("failure")

    def view(self, slot: str) -> SceneBatch:
        """The columns visible to ``slot``, by their plain names."""
        return SceneBatch.of({n: self._columns[k] for n, k in self._keys[slot].items()}, self.size)

    def take(self, index: np.ndarray) -> BoundBatch:
        """The bound batch of the scenes at ``index`` (integer or boolean array)."""
        columns = {k: c[index] for k, c in self._columns.items()}
        size = columns["radius"].size
        return BoundBatch(columns, self._keys, size)

    def __len__(self) -> int:
        return self.size


def bind_scenes(
    plugins: Sequence[tuple[str, Plugin]], onset: Any, rest_speed_fraction: float, batch: SceneBatch
) -> BoundBatch:
    """The batch with every per-scene constant the step loop needs, computed once and
    namespaced: the plate constants each plug-in (slot, plug-in) declared (checked
    against their ranges, or their defaults where the plate has none), the columns each
    prepared, ``onset_penetration`` [m] (``onset``, the failure model's
    ``onset_penetration`` on its view) and ``rest_speed`` [m/s], ``rest_speed_fraction``
    of the impact speed."""
    n = batch.size
    given = batch.columns
    columns = {name: given[name] for name in CORE_COLUMNS}
    keys: dict[str, dict[str, str]] = {}
    for slot, plugin in plugins:
        visible = {name: name for name in CORE_COLUMNS}
        for declared in plugin.plate_constants:
            if declared.name not in columns:
                columns[declared.name] = _constant_column(declared, given, n, slot, plugin)
            visible[declared.name] = declared.name
        view = SceneBatch.of({k: columns[v] for k, v in visible.items()}, n)
        prepared = plugin.prepare(view)
        for name, values in _checked_columns(slot, plugin, prepared, n).items():
            columns[f"{slot}.{name}"] = values
            visible[name] = f"{slot}.{name}"
        keys[slot] = visible
    failure_view = SceneBatch.of({k: columns[v] for k, v in keys["failure"].items()}, n)
    onset_penetration = np.broadcast_to(np.asarray(onset(failure_view), dtype=float), (n,))
    ONSET_PENETRATION.check(onset_penetration)
    columns["onset_penetration"] = np.ascontiguousarray(onset_penetration)
    columns["rest_speed"] = rest_speed_fraction * given["impact_speed"]
    keys["core"] = {name: name for name in (*CORE_COLUMNS, "onset_penetration", "rest_speed")}
    return BoundBatch(columns, keys, n)


def check_declarations(plugins: dict[str, Any]) -> None:
    """Refuse, with one line, plug-ins whose declarations clash: one plate constant
    declared two ways, or a prepared column that shadows a core column or constant."""
    seen: dict[str, tuple[Parameter, str]] = {}
    for slot, plugin in plugins.items():
        label = f"{slot} {plugin.name!r}"
        for declared in plugin.plate_constants:
            if declared.name in CORE_COLUMNS:
                raise PluginError(
                    f"{label} declares plate constant {declared.name!r}, a core column"
                )
            if declared.name in seen and seen[declared.name][0] != declared:
                raise PluginError(
                    f"{seen[declared.name][1]} and {label} both claim plate constant "
                    f"{declared.name!r} with different declarations"
                )
            seen.setdefault(declared.name, (declared, label))
        shadowed = {c.name for c in plugin.columns} & (
            set(CORE_COLUMNS) | {p.name for p in plugin.plate_constants}
        )
        if shadowed:
            raise PluginError(f"{label} prepares column {sorted(shadowed)[0]!r}, a name it reads")


def _constant_column(
    declared: Parameter, given: dict[str, np.ndarray], n: int, slot: str, plugin: Plugin
) -> np.ndarray:
    """The plate constant a plug-in declared: the plate's, checked, or its default."""
    if declared.name in given:
        declared.check(given[declared.name])
        return given[declared.name]
    if declared.has_default:
        return np.full(n, float(declared.default))  # type: ignore[arg-type]
    raise ParameterError(
        declared.name,
        f"{declared.name} ({declared.description}) is needed by {slot} {plugin.name!r} and "
        f"has no default: give the plate one ({declared.describe_range()})",
    )


def _checked_columns(
    slot: str, plugin: Plugin, prepared: dict[str, Any], n: int
) -> dict[str, np.ndarray]:
    """The columns a plug-in prepared, exactly those it declared, one float per scene."""
    declared = [c.name for c in plugin.columns]
    if set(prepared) != set(declared):
        extra, missing = (
            sorted(set(prepared) - set(declared)),
            sorted(set(declared) - set(prepared)),
        )
        what = f"undeclared column {extra[0]!r}" if extra else f"no column {missing[0]!r}"
        raise PluginError(f"{slot} {plugin.name!r}: prepare() returned {what}")
    return {
        name: np.ascontiguousarray(np.broadcast_to(np.asarray(prepared[name], float), (n,)))
        for name in declared
    }
