"""A batch bound to a model: the driver's columns and each plug-in's namespaced view."""

from __future__ import annotations

import numpy as np

from .batch import SceneBatch

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
