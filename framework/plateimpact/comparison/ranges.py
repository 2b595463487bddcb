"""Run B against run A on the same scenes: where the outcome changes, in ranges.

The scenes fall into rows: per plate, the scenes at one impact obliquity sorted by impact
speed; or, for a plate with fewer distinct speeds than obliquities (an obliquity sweep),
the scenes at one speed sorted by obliquity. Along a row, consecutive scenes whose regime
(outcome and plate state, :class:`~plateimpact.limits.Regime`) goes the same way from A
to B, and differs, make one :class:`OutcomeRange`.

Differences are B − A. The exit speed of an embedment is 0, so an embedment against a
perforation differs by the perforation's residual speed. Exit obliquities are compared
only where the sphere leaves the plate in both runs (ricochet or perforation): an
embedment's recorded obliquity is its direction at rest, not an exit. Where no scene of a
range leaves in both, its exit-obliquity difference is None (JSON null), never NaN.
"""

from __future__ import annotations

import math
from collections.abc import Iterable
from typing import Any

import attrs
import numpy as np

from ..base.errors import ParameterError
from ..limits.lines import OBLIQUITY, SPEED, unit_suffix
from ..limits.regimes import Regime, regime_codes
from ..model.batch import SceneBatch
from ..model.results import BatchResult, Outcome

_DEG = math.pi / 180.0


def _user(axis: str, value: float) -> float:
    """``value`` [m/s or rad] in user units [m/s or deg]; 45, not 45.00000000000001."""
    return float(f"{value / _DEG:.12g}") if axis == OBLIQUITY else float(value)


def _largest(change: np.ndarray, where: np.ndarray) -> float | None:
    """The largest |change| over the scenes ``where`` (a mask); None if there are none."""
    return float(np.max(np.abs(change[where]))) if np.any(where) else None


def _spread(
    index: np.ndarray, speed_change: np.ndarray, obliquity_change: np.ndarray, leave: np.ndarray
) -> Spread:
    """The largest exit differences over the scenes ``index`` (obliquity: where ``leave``)."""
    every = np.ones(index.size, dtype=bool)
    return Spread(
        int(index.size),
        _largest(speed_change[index], every),
        _largest(obliquity_change[index], leave[index]),
    )


def _degrees(value: float | None) -> float | None:
    return None if value is None else value / _DEG


def _strings(values: Iterable[object]) -> tuple[str, ...]:
    return tuple(str(v) for v in values)


def _place(plate: str, axis: str, fixed: float, start: float, end: float) -> dict[str, Any]:
    """Where a row or range is, in user units: ``obliquity_deg``, ``from_m_s``, ``to_m_s``
    along speed; ``speed_m_s``, ``from_deg``, ``to_deg`` along obliquity."""
    unit = unit_suffix(axis)
    other = OBLIQUITY if axis == SPEED else SPEED
    return {
        "plate": plate,
        "axis": axis,
        f"{'obliquity' if axis == SPEED else 'speed'}_{unit_suffix(other)}": _user(other, fixed),
        f"from_{unit}": _user(axis, start),
        f"to_{unit}": _user(axis, end),
    }


@attrs.frozen(eq=False)
class Spread:
    """How far B's exits differ from A's over some scenes.

    ``max_abs_exit_speed_change`` [m/s] (None: no scenes); ``max_abs_exit_obliquity_change``
    [rad] over the scenes where the sphere leaves the plate in both runs (None: none).
    """

    scenes: int
    max_abs_exit_speed_change: float | None
    max_abs_exit_obliquity_change: float | None

    def to_json(self, prefix: str = "") -> dict[str, Any]:
        """User units, the unit in every key (``max_abs_delta_exit_speed_m_s``)."""
        return {
            f"{prefix}scenes": self.scenes,
            f"{prefix}max_abs_delta_exit_speed_m_s": self.max_abs_exit_speed_change,
            f"{prefix}max_abs_delta_exit_obliquity_deg": _degrees(
                self.max_abs_exit_obliquity_change
            ),
        }


@attrs.frozen(eq=False)
class OutcomeRange:
    """Consecutive scenes of a row that end in ``regime_a`` in run A and ``regime_b`` in B.

    Attributes
    ----------
    plate : str
        The plate's label.
    axis : str
        ``impact_speed`` or ``impact_obliquity``: what varies along the row.
    fixed : float
        The row's impact obliquity [rad] (along speed) or impact speed [m/s].
    start, end : float
        The first and last scene's impact speed [m/s] (or impact obliquity [rad]).
    regime_a, regime_b : Regime
    spread : Spread
        The largest exit differences over the range.
    index : ndarray
        The scenes, in the study's numbering, along the row.
    """

    plate: str
    axis: str
    fixed: float
    start: float
    end: float
    regime_a: Regime
    regime_b: Regime
    spread: Spread
    index: np.ndarray = attrs.field(repr=False)

    @property
    def pair(self) -> str:
        """``perforation -> embedment``: the change, as text and JSON name it."""
        return f"{self.regime_a.label} -> {self.regime_b.label}"

    def to_json(self) -> dict[str, Any]:
        """User units, the unit in every key (``from_m_s``, ``obliquity_deg``)."""
        return {
            **_place(self.plate, self.axis, self.fixed, self.start, self.end),
            "outcome_a": self.regime_a.label,
            "outcome_b": self.regime_b.label,
            "plate_failed_a": self.regime_a.plate_failed,
            "plate_failed_b": self.regime_b.plate_failed,
            **self.spread.to_json(),
        }


@attrs.frozen(eq=False)
class ComparisonRow:
    """One plate at one obliquity (or one speed): its outcome ranges, and the exit
    differences over its scenes whose regime is the same in both runs (``same``).
    ``plate``, ``axis``, ``fixed``, ``start``, ``end``, ``index`` as in :class:`OutcomeRange`."""

    plate: str
    axis: str
    fixed: float
    start: float
    end: float
    ranges: tuple[OutcomeRange, ...]
    same: Spread
    index: np.ndarray = attrs.field(repr=False)

    @property
    def changed_scenes(self) -> int:
        return sum(r.spread.scenes for r in self.ranges)

    def to_json(self) -> dict[str, Any]:
        """User units, the unit in every key; the ranges are listed on their own."""
        return {
            **_place(self.plate, self.axis, self.fixed, self.start, self.end),
            "scenes": int(self.index.size),
            "changed_scenes": self.changed_scenes,
            "ranges": len(self.ranges),
            **self.same.to_json("same_outcome_"),
        }


@attrs.frozen(eq=False)
class Comparison:
    """Run B against run A on the same scenes (``StudyResults.compare`` makes it).

    ``scenes`` and ``plate_labels`` are the study's; ``result_a`` and ``result_b`` hold
    one entry per scene.
    """

    run_a: str
    run_b: str
    result_a: BatchResult
    result_b: BatchResult
    scenes: SceneBatch
    plate_labels: tuple[str, ...] = attrs.field(converter=_strings)

    def __attrs_post_init__(self) -> None:
        sizes = {len(self.result_a), len(self.result_b), len(self.scenes), len(self.plate_labels)}
        if len(sizes) != 1:
            raise ParameterError(
                "runs",
                f"runs {self.run_a!r} ({len(self.result_a)} scenes) and {self.run_b!r} "
                f"({len(self.result_b)}) must cover the same {len(self.scenes)} scenes",
            )

    @property
    def outcome_a(self) -> np.ndarray:
        return self.result_a.outcome

    @property
    def outcome_b(self) -> np.ndarray:
        return self.result_b.outcome

    @property
    def changed(self) -> np.ndarray:
        """Indices of the scenes whose regime (outcome or plate state) differs."""
        return np.flatnonzero(regime_codes(self.result_a) != regime_codes(self.result_b))

    @property
    def both_leave(self) -> np.ndarray:
        """Per scene: whether the sphere leaves the plate in both runs (no embedment)."""
        embedded = (self.outcome_a == Outcome.EMBEDMENT) | (self.outcome_b == Outcome.EMBEDMENT)
        return ~embedded

    @property
    def exit_speed_change(self) -> np.ndarray:
        """Per scene, B − A [m/s] (an embedment's exit speed is 0)."""
        return self.result_b.exit_speed - self.result_a.exit_speed

    @property
    def exit_obliquity_change(self) -> np.ma.MaskedArray:
        """Per scene, B − A [rad]; masked where either run embeds (no exit direction)."""
        change, leave = self._obliquity_change()
        return np.ma.MaskedArray(change, mask=~leave)

    def _obliquity_change(self) -> tuple[np.ndarray, np.ndarray]:
        """B − A [rad] where both runs leave the plate (0 elsewhere), and that mask."""
        leave = self.both_leave
        change = self.result_b.exit_obliquity - self.result_a.exit_obliquity
        return np.where(leave, change, 0.0), leave

    def spread(self, index: np.ndarray | None = None) -> Spread:
        """The exit differences over the scenes ``index`` (default: every scene)."""
        index = np.arange(len(self.scenes)) if index is None else np.asarray(index, dtype=int)
        return _spread(index, self.exit_speed_change, *self._obliquity_change())

    def same_outcome(self) -> Spread:
        """The exit differences over the scenes whose regime is the same in both runs."""
        return self.spread(np.setdiff1d(np.arange(len(self.scenes)), self.changed))

    def _lines(self) -> list[tuple[str, str, float, np.ndarray]]:
        """(plate, axis, fixed value, scene indices along the axis) per row."""
        labels = np.asarray(self.plate_labels)
        speed = np.asarray(self.scenes.impact_speed)
        obliquity = np.asarray(self.scenes.impact_obliquity)
        degrees = np.round(np.degrees(obliquity), 6)  # 45 deg from any path to radians
        found = []
        for plate in dict.fromkeys(self.plate_labels):
            mine = np.flatnonzero(labels == plate)
            sweep = np.unique(speed[mine]).size < np.unique(degrees[mine]).size
            key, along, axis = (speed, obliquity, OBLIQUITY) if sweep else (degrees, speed, SPEED)
            for value in np.unique(key[mine]):
                row = mine[key[mine] == value]
                row = row[np.argsort(along[row], kind="stable")]
                fixed = speed[row[0]] if sweep else obliquity[row[0]]
                found.append((str(plate), axis, float(fixed), row))
        return found

    def rows(self) -> tuple[ComparisonRow, ...]:
        """Every row: plates in the study's order, fixed values rising."""
        code_a, code_b = regime_codes(self.result_a), regime_codes(self.result_b)
        changes = (self.exit_speed_change, *self._obliquity_change())  # once, not per range
        along = {SPEED: self.scenes.impact_speed, OBLIQUITY: self.scenes.impact_obliquity}
        rows = []
        for plate, axis, fixed, row in self._lines():
            position = along[axis]
            a, b = code_a[row], code_b[row]
            starts = np.flatnonzero(np.r_[True, (a[1:] != a[:-1]) | (b[1:] != b[:-1])])
            ends = np.r_[starts[1:], row.size]
            ranges = tuple(
                OutcomeRange(
                    plate,
                    axis,
                    fixed,
                    float(position[row[s]]),
                    float(position[row[e - 1]]),
                    Regime.of_code(a[s]),
                    Regime.of_code(b[s]),
                    _spread(row[s:e], *changes),
                    row[s:e],
                )
                for s, e in zip(starts, ends, strict=True)
                if a[s] != b[s]
            )
            same = row[a == b]
            rows.append(
                ComparisonRow(
                    plate,
                    axis,
                    fixed,
                    float(position[row[0]]),
                    float(position[row[-1]]),
                    ranges,
                    _spread(same, *changes),
                    row,
                )
            )
        return tuple(rows)

    def ranges(self) -> tuple[OutcomeRange, ...]:
        """Every outcome range, row by row, along each row."""
        return tuple(r for row in self.rows() for r in row.ranges)

    def summary(self) -> dict[str, Any]:
        """Counts only, user units: scenes, changed scenes and ranges, the scenes of each
        change (most first), the largest exit differences over all scenes and over the
        scenes whose outcome is the same."""
        return self._summary(self.rows())

    def _summary(self, rows: tuple[ComparisonRow, ...]) -> dict[str, Any]:
        changes: dict[str, int] = {}
        for r in (r for row in rows for r in row.ranges):
            changes[r.pair] = changes.get(r.pair, 0) + r.spread.scenes
        overall = self.spread().to_json()
        return {
            "scenes": overall.pop("scenes"),
            "changed_scenes": int(self.changed.size),
            "ranges": sum(len(row.ranges) for row in rows),
            "changes": dict(sorted(changes.items(), key=lambda item: -item[1])),
            **overall,
            "same_outcome": self.same_outcome().to_json(),
        }

    def to_json(self) -> dict[str, Any]:
        """The runs, :meth:`summary`, every row and every outcome range (user units)."""
        rows = self.rows()
        return {
            "a": self.run_a,
            "b": self.run_b,
            "difference": "b - a",
            **self._summary(rows),
            "rows": [row.to_json() for row in rows],
            "outcome_ranges": [r.to_json() for row in rows for r in row.ranges],
        }
