"""Contiguous ragged arrays (CF conventions): many variable-length rows in flat arrays.

Trajectories (one row of samples per scene) and crater sections (one row of points per
scene) are both stored this way: every row's samples concatenated in ``values[name]``,
row ``i`` owning the slice ``offsets[i]:offsets[i + 1]``, with ``offsets`` the running
sum of ``counts``. Per-row values (one per scene) sit in ``per_row``.
"""

from __future__ import annotations

from collections.abc import Mapping, Sequence

import numpy as np


class Ragged:
    """Rows of variable length over shared columns.

    Parameters
    ----------
    counts : array of int
        Samples per row, in row order.
    values : mapping of name to array
        Per-sample columns, each of length ``counts.sum()``.
    per_row : mapping of name to array, optional
        Per-row columns, each of length ``len(counts)``.
    """

    __slots__ = ("counts", "offsets", "per_row", "values")

    def __init__(
        self,
        counts: np.ndarray,
        values: Mapping[str, np.ndarray],
        per_row: Mapping[str, np.ndarray] | None = None,
    ) -> None:
        self.counts = np.asarray(counts, dtype=np.int64)
        self.offsets = np.concatenate([[0], np.cumsum(self.counts)]).astype(np.int64)
        self.values = {k: np.asarray(v) for k, v in values.items()}
        self.per_row = {k: np.asarray(v) for k, v in (per_row or {}).items()}
        total = int(self.offsets[-1])
        for name, column in self.values.items():
            if column.shape != (total,):
                raise ValueError(f"ragged column {name!r} has {column.shape}, expected ({total},)")
        for name, column in self.per_row.items():
            if column.shape != self.counts.shape:
                raise ValueError(f"per-row column {name!r} has {column.shape}, not one per row")

    @classmethod
    def from_samples(
        cls, rows: int, row: np.ndarray, values: Mapping[str, np.ndarray], order_by: str
    ) -> Ragged:
        """Samples in any order, ``row[k]`` the row of sample k: grouped by row and, within
        a row, ordered by the column ``order_by`` (e.g. time)."""
        order = np.lexsort((values[order_by], row))
        counts = np.bincount(row, minlength=rows)
        return cls(counts, {k: v[order] for k, v in values.items()})

    @classmethod
    def from_rows(
        cls, rows: Sequence[Mapping[str, np.ndarray]], per_row: Mapping[str, Sequence[float]]
    ) -> Ragged:
        """Rows given one by one (each a mapping of column to its samples)."""
        names = list(rows[0]) if rows else []
        counts = np.array([len(next(iter(r.values()))) for r in rows], dtype=np.int64)
        values = {k: np.concatenate([r[k] for r in rows]) if rows else np.zeros(0) for k in names}
        return cls(counts, values, {k: np.asarray(v, dtype=float) for k, v in per_row.items()})

    @classmethod
    def concat(cls, parts: Sequence[Ragged]) -> Ragged:
        """The rows of ``parts`` in order."""
        first = parts[0]
        return cls(
            np.concatenate([p.counts for p in parts]),
            {k: np.concatenate([p.values[k] for p in parts]) for k in first.values},
            {k: np.concatenate([p.per_row[k] for p in parts]) for k in first.per_row},
        )

    def __len__(self) -> int:
        return int(self.counts.size)

    def __getitem__(self, name: str) -> np.ndarray:
        """A per-sample column, or else a per-row one."""
        if name in self.values:
            return self.values[name]
        return self.per_row[name]

    def __contains__(self, name: object) -> bool:
        return name in self.values or name in self.per_row

    def row(self, i: int) -> dict[str, np.ndarray]:
        """The samples of row ``i`` by column (views, no copy)."""
        lo, hi = self.offsets[i], self.offsets[i + 1]
        return {k: v[lo:hi] for k, v in self.values.items()}

    def take(self, index: np.ndarray) -> Ragged:
        """The rows at ``index`` (integer array, repeats allowed), in that order."""
        index = np.asarray(index, dtype=np.int64)
        counts = self.counts[index]
        starts = self.offsets[:-1][index]
        # Sample positions: each row's start plus 0 .. count − 1, without a Python loop.
        within = np.arange(int(counts.sum())) - np.repeat(np.cumsum(counts) - counts, counts)
        samples = np.repeat(starts, counts) + within
        return Ragged(
            counts,
            {k: v[samples] for k, v in self.values.items()},
            {k: v[index] for k, v in self.per_row.items()},
        )
