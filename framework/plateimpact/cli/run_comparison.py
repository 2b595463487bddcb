"""``compare`` of two runs: outcome changes in ranges, as text, counts or JSON (run names
and plate labels, from the archive, printed inert: describe.shown)."""

from __future__ import annotations

import json

from ..comparison import Comparison, ComparisonRow, OutcomeRange, Spread
from ..limits.lines import OBLIQUITY, SPEED
from .formatting import ANGLE, AXES, IMPACT_SPEED, number, quantity, shown, unit
from .writer import Writer


def _place(axis: str, start: float, end: float) -> str:
    """``400-1500 m/s`` along speed, ``10-85 deg`` along obliquity (one value if equal)."""
    declared = AXES[axis]
    texts = [number(declared, v) for v in (start, end)]
    where = texts[0] if texts[0] == texts[1] else f"{texts[0]}-{texts[1]}"
    return f"{where} {unit(declared)}"


def _count(count: int, thing: str) -> str:
    return f"{count} {thing}" if count == 1 else f"{count} {thing}s"


def _scenes(count: int) -> str:
    return _count(count, "scene")


def _head(comparison: Comparison, changed: int, ranges: int) -> str:
    return (
        f"B {shown(comparison.run_b, None)} against A {shown(comparison.run_a, None)}: "
        f"{_scenes(len(comparison.scenes))}, {changed} with another outcome in "
        f"{_count(ranges, 'range')}"
    )


def _spread(spread: Spread) -> str:
    """``exit speed differs by up to 85.2 m/s, exit obliquity by up to 3.1 deg``."""
    speed, obliquity = spread.max_abs_exit_speed_change, spread.max_abs_exit_obliquity_change
    if speed is None:
        return "no scenes"
    text = f"exit speed differs by up to {quantity(IMPACT_SPEED, speed, 1, 'f')}"
    if obliquity is None:
        return f"{text} (embedded: no exit obliquity)"
    return f"{text}, exit obliquity by up to {quantity(ANGLE, obliquity, 1, 'f')}"


def _row_head(row: ComparisonRow) -> str:
    other = AXES[OBLIQUITY if row.axis == SPEED else SPEED]
    at = quantity(other, row.fixed)
    return f"{shown(row.plate)} at {at}, {_place(row.axis, row.start, row.end)}"


def _range(change: OutcomeRange) -> str:
    return (
        f"  {_place(change.axis, change.start, change.end)} ({_scenes(change.spread.scenes)}): "
        f"{change.pair}; {_spread(change.spread)}"
    )


def text(comparison: Comparison) -> str:
    """Per row: its ranges of changed outcome, then the scenes whose outcome is the same."""
    rows = comparison.rows()
    changed = sum(row.changed_scenes for row in rows)
    ranges = sum(len(row.ranges) for row in rows)
    out = [f"{_head(comparison, changed, ranges)} (differences B - A)"]
    for row in rows:
        same = row.same
        if not row.ranges:
            out.append(f"{_row_head(row)}: the same outcome throughout; {_spread(same)}")
            continue
        out.append(f"{_row_head(row)} ({_scenes(int(row.index.size))}):")
        out += [_range(change) for change in row.ranges]
        if same.scenes:
            out.append(f"  the same outcome elsewhere ({_scenes(same.scenes)}): {_spread(same)}")
    return "\n".join(out)


def summary_text(comparison: Comparison) -> str:
    """The counts: scenes, changes by pair, the largest exit differences."""
    summary = comparison.summary()
    same = comparison.same_outcome()
    out = [_head(comparison, summary["changed_scenes"], summary["ranges"])]
    out += [f"  {pair}: {_scenes(count)}" for pair, count in summary["changes"].items()]
    out.append(f"  all scenes: {_spread(comparison.spread())}")
    out.append(f"  the same outcome ({_scenes(same.scenes)}): {_spread(same)}")
    return "\n".join(out)


def print_comparison(comparison: Comparison, out: Writer, *, as_json: bool, summary: bool) -> None:
    """Print the comparison: ranges as text, or counts only, or one JSON object."""
    if as_json:
        runs = {"a": comparison.run_a, "b": comparison.run_b}
        found = {**runs, **comparison.summary()} if summary else comparison.to_json()
        out.say(json.dumps(found, indent=2))
    else:
        out.say(summary_text(comparison) if summary else text(comparison))
