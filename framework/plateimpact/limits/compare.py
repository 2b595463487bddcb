"""How far each boundary moved between two sets of limits (``plateimpact compare``).

Lines are matched by their fixed value (obliquity or speed, to a relative 1e-9); on a
pair of lines, boundaries are matched by their (below, above) regime pair, the k-th
such boundary of A with the k-th of B; bands by their regime, likewise. What has no
partner is reported as present in one only.
"""

from __future__ import annotations

import math
from collections import defaultdict
from collections.abc import Callable, Hashable, Sequence
from typing import Any, TypeVar

import attrs

from ..base.errors import ParameterError
from . import views
from .lines import OBLIQUITY, SPEED, Band, Boundary, LimitLine, unit_suffix
from .maps import OutcomeMap
from .plate_limits import Limits
from .regimes import Regime

_DEG = math.pi / 180.0
T = TypeVar("T")


def user(axis: str, value: float) -> float:
    """``value`` [SI] on ``axis`` in user units (m/s or degrees)."""
    return value / _DEG if axis == OBLIQUITY else value


@attrs.frozen
class BoundaryShift:
    """One boundary (``below`` to ``above``) in A and in B; ``a`` or ``b`` is None when
    only the other has it."""

    below: Regime
    above: Regime
    a: Boundary | None
    b: Boundary | None

    @property
    def shift(self) -> float | None:
        """B's position minus A's [m/s or rad]; None unless both have it."""
        return None if self.a is None or self.b is None else self.b.at - self.a.at

    @property
    def position(self) -> float:
        """Where it is: in A if A has it, else in B."""
        either = self.a if self.a is not None else self.b
        return math.nan if either is None else either.at


@attrs.frozen
class LineComparison:
    """A line present in both: its boundaries, matched, and its bands in one only."""

    fixed: float
    boundaries: tuple[BoundaryShift, ...]
    bands_only_in_a: tuple[Band, ...]
    bands_only_in_b: tuple[Band, ...]


@attrs.frozen(repr=False)
class LimitsComparison:
    """``lines``: the lines both have; ``lines_only_in_a``, ``lines_only_in_b``: the
    fixed values of the others [rad or m/s]."""

    axis: str
    tolerance_a: float
    tolerance_b: float
    lines: tuple[LineComparison, ...]
    lines_only_in_a: tuple[float, ...]
    lines_only_in_b: tuple[float, ...]

    @property
    def fixed_axis(self) -> str:
        return OBLIQUITY if self.axis == SPEED else SPEED

    def __repr__(self) -> str:
        return views.comparison_repr(self)

    def _repr_html_(self) -> str:
        return views.comparison_html(self)

    def to_json(self) -> dict[str, Any]:
        """In user units, the unit in every key (``shift_m_s`` or ``shift_deg``)."""
        unit, fixed = unit_suffix(self.axis), unit_suffix(self.fixed_axis)
        fixed_key = f"{'obliquity' if self.axis == SPEED else 'speed'}_{fixed}"

        def band(b: Band) -> dict[str, Any]:
            return {
                **b.regime.to_json(),
                "regime": b.regime.label,
                f"from_{unit}": user(self.axis, b.start),
                f"to_{unit}": user(self.axis, b.end),
            }

        def at(boundary: Boundary | None) -> float | None:
            return None if boundary is None else user(self.axis, boundary.at)

        def shift(s: BoundaryShift) -> dict[str, Any]:
            moved = s.shift
            return {
                "below": s.below.label,
                "above": s.above.label,
                f"a_{unit}": at(s.a),
                f"b_{unit}": at(s.b),
                f"shift_{unit}": None if moved is None else user(self.axis, moved),
            }

        return {
            "axis": self.axis,
            f"tolerance_a_{unit}": user(self.axis, self.tolerance_a),
            f"tolerance_b_{unit}": user(self.axis, self.tolerance_b),
            "lines": [
                {
                    fixed_key: user(self.fixed_axis, line.fixed),
                    "boundaries": [shift(s) for s in line.boundaries],
                    "bands_only_in_a": [band(b) for b in line.bands_only_in_a],
                    "bands_only_in_b": [band(b) for b in line.bands_only_in_b],
                }
                for line in self.lines
            ],
            f"lines_only_in_a_{fixed}": [user(self.fixed_axis, x) for x in self.lines_only_in_a],
            f"lines_only_in_b_{fixed}": [user(self.fixed_axis, x) for x in self.lines_only_in_b],
        }


def _pair(
    a: Sequence[T], b: Sequence[T], key: Callable[[T], Hashable]
) -> tuple[list[tuple[T, T]], list[T], list[T]]:
    """The k-th item of A with the k-th of B having the same ``key``; the rest."""
    pending: dict[Hashable, list[T]] = defaultdict(list)
    for item in b:
        pending[key(item)].append(item)
    pairs, only_a = [], []
    for item in a:
        partners = pending[key(item)]
        if partners:
            pairs.append((item, partners.pop(0)))
        else:
            only_a.append(item)
    taken = {id(y) for _, y in pairs}
    return pairs, only_a, [y for y in b if id(y) not in taken]


def _compare_lines(a: LimitLine, b: LimitLine) -> LineComparison:
    def regimes(x: Boundary) -> tuple[Regime, Regime]:
        return (x.below, x.above)

    pairs, only_a, only_b = _pair(a.boundaries, b.boundaries, regimes)
    shifts = [BoundaryShift(x.below, x.above, x, y) for x, y in pairs]
    shifts += [BoundaryShift(x.below, x.above, x, None) for x in only_a]
    shifts += [BoundaryShift(y.below, y.above, None, y) for y in only_b]
    shifts.sort(key=lambda s: s.position)
    _, bands_a, bands_b = _pair(a.bands, b.bands, lambda band: band.regime)
    return LineComparison(a.fixed, tuple(shifts), tuple(bands_a), tuple(bands_b))


def _limits(found: object, which: str) -> Limits:
    if isinstance(found, OutcomeMap):
        return found.limits
    if isinstance(found, Limits):
        return found
    raise ParameterError(which, f"{which} must be Limits or an OutcomeMap, got {found!r:.60}")


def compare_limits(a: Limits | OutcomeMap, b: Limits | OutcomeMap) -> LimitsComparison:
    """How each boundary moved from ``a`` to ``b`` (limits, or maps: their rows'
    limits). Both must run along the same axis."""
    first, second = _limits(a, "a"), _limits(b, "b")
    if first.axis != second.axis:
        raise ParameterError(
            "b",
            f"limits along {first.axis} cannot be compared with limits along {second.axis}",
        )

    def same(x: LimitLine, y: LimitLine) -> bool:
        return math.isclose(x.fixed, y.fixed, rel_tol=1e-9, abs_tol=1e-12)

    lines, only_a = [], []
    unmatched = list(second.lines)
    for line in first.lines:
        k = next((k for k, y in enumerate(unmatched) if same(line, y)), None)
        if k is None:
            only_a.append(line.fixed)
        else:
            lines.append(_compare_lines(line, unmatched.pop(k)))
    return LimitsComparison(
        first.axis,
        first.tolerance,
        second.tolerance,
        tuple(lines),
        tuple(only_a),
        tuple(y.fixed for y in unmatched),
    )
