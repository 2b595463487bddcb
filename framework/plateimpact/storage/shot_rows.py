"""The columns of a shot file and the checks of one row (for :mod:`.shots`).

Each row is read into user units and checked on its own; a bad value raises
:class:`BadValue` naming the column, which the reader (:mod:`.shot_reader`) turns into
one line naming the file, line, column and value (and how many more rows are bad).
"""

from __future__ import annotations

import math
from collections.abc import Mapping, Sequence

import attrs
import numpy as np

from ..base.errors import ShotDataError
from ..base.parameters import Parameter
from ..model.bodies import MASS, RADIUS
from ..model.results import RESULT_FIELDS, Outcome
from ..model.scene import IMPACT_OBLIQUITY, IMPACT_SPEED

RESIDUAL_SPEED = Parameter(
    "residual_speed",
    "speed when contact ends: through the plate, or of a ricochet (0: did not perforate)",
    "m/s",
)
#: Columns every file has.
REQUIRED_COLUMNS = (IMPACT_SPEED.key, IMPACT_OBLIQUITY.key)
#: Columns of which a file has at least one: each shot must say whether it perforated.
PERFORATION_COLUMNS = (RESIDUAL_SPEED.key, "perforated", "outcome")
#: Every column read, in the order files are written.
COLUMNS = (
    *REQUIRED_COLUMNS,
    "outcome",
    "perforated",
    RESIDUAL_SPEED.key,
    RESULT_FIELDS["exit_obliquity"].key,
    RADIUS.key,
    MASS.key,
    "weight",
    "source",
)
#: The keys of the checked columns, once (each row reads them; ``Parameter.key`` builds
#: its string on every call).
SPEED_KEY, OBLIQUITY_KEY = REQUIRED_COLUMNS
RESIDUAL_KEY, EXIT_KEY = RESIDUAL_SPEED.key, RESULT_FIELDS["exit_obliquity"].key
_RANGES = {declared.name: (declared.key, declared.describe_range()) for declared in (RADIUS, MASS)}
#: How the ``perforated`` column may say yes and no.
PERFORATED_WORDS = {"1": True, "0": False, "true": True, "false": False}
_OUTCOMES = {o.label: o for o in Outcome}


class BadValue(Exception):
    """One bad value in a row: the column and what is wrong with it."""

    def __init__(self, column: str, problem: str) -> None:
        super().__init__(column, problem)
        self.column, self.problem = column, problem


@attrs.frozen
class ShotRow:
    """One checked row, in user units (m/s, deg, mm, g); NaN or 0 where not given."""

    impact_speed: float
    impact_obliquity: float
    outcome: int
    perforated: bool
    residual_speed: float
    exit_obliquity: float
    radius: float
    mass: float
    weight: float
    note: str


def check_columns(where: str, names: Sequence[str]) -> None:
    """Raise :class:`ShotDataError` for a repeated column or a missing required one."""
    duplicated = sorted({n for n in names if names.count(n) > 1})
    if duplicated:
        raise ShotDataError(f"{where}: column {duplicated[0]} appears more than once")
    header = f"(header has: {', '.join(names) or 'nothing'})"
    missing = [c for c in REQUIRED_COLUMNS if c not in names]
    if missing:
        plural = "s" if len(missing) > 1 else ""
        raise ShotDataError(f"{where}: missing column{plural} {', '.join(missing)} {header}")
    if not any(c in names for c in PERFORATION_COLUMNS):
        first, *others = PERFORATION_COLUMNS
        raise ShotDataError(
            f"{where}: missing column {first}, {' or '.join(others)} (each shot must say "
            f"whether it perforated) {header}"
        )


def _number(value: object) -> float:
    """A float from a number or a string; ValueError for anything else."""
    if isinstance(value, bool):
        raise ValueError
    if isinstance(value, str):
        return float(value.strip())
    if isinstance(value, int | float | np.integer | np.floating):
        return float(value)
    raise ValueError


def _is_blank(value: object) -> bool:
    return value is None or (isinstance(value, str) and not value.strip())


def _finite(row: Mapping[str, object], column: str, *, optional: bool = True) -> float:
    """The number in ``column``, NaN if blank (when ``optional``); BadValue otherwise."""
    raw = row.get(column)
    if optional and _is_blank(raw):
        return math.nan
    try:
        x = _number(raw)
    except (TypeError, ValueError):
        raise BadValue(column, f"not a number, got {raw!r}") from None
    if not math.isfinite(x):
        raise BadValue(column, f"must be finite, got {raw!r}")
    return x


def _inside(declared: Parameter, x: float) -> bool:
    """Whether ``x`` [SI], finite, lies in ``declared``'s range (a scalar Range.contains)."""
    r = declared.range
    above = x > r.low if r.low_open else x >= r.low
    return above and (x < r.high if r.high_open else x <= r.high)


def _in_range(row: Mapping[str, object], declared: Parameter) -> float:
    """An optional number in ``declared``'s range (user units), NaN if blank."""
    key, allowed = _RANGES[declared.name]
    x = _finite(row, key)
    if not math.isnan(x) and not _inside(declared, x * declared.scale):
        raise BadValue(key, f"must be {allowed}, got {row[key]!r}")
    return x


def _outcome(row: Mapping[str, object]) -> int:
    raw = row.get("outcome")
    if _is_blank(raw):
        return 0
    label = str(raw).strip().lower()
    if label not in _OUTCOMES:
        raise BadValue("outcome", f"must be one of {', '.join(_OUTCOMES)} or empty, got {raw!r}")
    return int(_OUTCOMES[label])


def _perforated(row: Mapping[str, object]) -> bool | None:
    raw = row.get("perforated")
    if _is_blank(raw):
        return None
    word = str(raw).strip().lower()
    if not isinstance(raw, str | bool | np.bool_):  # a number from Python columns
        try:
            word = f"{_number(raw):g}"
        except (TypeError, ValueError):
            pass
    if word not in PERFORATED_WORDS:
        raise BadValue("perforated", f"must be 1 or 0 (true or false) or empty, got {raw!r}")
    return PERFORATED_WORDS[word]


def _perforation(row: Mapping[str, object], outcome: int, residual: float) -> bool:
    """Whether the shot perforated, from what the row says, which must agree."""
    said = _perforated(row)
    if outcome and said is not None and said != (outcome == Outcome.PERFORATION):
        raise BadValue(
            "perforated", f"{row['perforated']!r} contradicts outcome {Outcome(outcome).label}"
        )
    if said is None and outcome:
        said = outcome == Outcome.PERFORATION
    if said is None and not math.isnan(residual):
        said = residual > 0.0
    if said is None:
        raise BadValue(
            "outcome",
            "each shot must say whether it perforated: give an outcome, perforated (1 or 0) "
            "or a residual speed",
        )
    column, what = ("outcome", Outcome(outcome).label) if outcome else ("perforated", "")
    if said and residual == 0.0:
        raise BadValue(
            column,
            f"{what or 'perforated 1'} contradicts residual speed 0 m/s (a perforation "
            "leaves with a speed > 0; leave it empty if not measured)",
        )
    # Only a perforation or a ricochet leaves the plate with a speed.
    if not said and residual > 0.0 and outcome != Outcome.RICOCHET:
        raise BadValue(
            column,
            f"{what or 'perforated 0'} contradicts residual speed {residual:g} m/s (only a "
            "perforation or a ricochet leaves with a speed)",
        )
    return said


def check_row(row: Mapping[str, object]) -> ShotRow:
    """One row (column name -> number or string, user units) checked; BadValue if bad."""
    speed = _finite(row, SPEED_KEY, optional=False)
    if not _inside(IMPACT_SPEED, speed):
        raw = row[SPEED_KEY]
        raise BadValue(SPEED_KEY, f"must be {IMPACT_SPEED.describe_range()}, got {raw!r}")
    obliquity = _finite(row, OBLIQUITY_KEY, optional=False)
    if not 0.0 <= obliquity < 90.0:
        raise BadValue(OBLIQUITY_KEY, f"must be in [0, 90) deg, got {row[OBLIQUITY_KEY]!r}")
    residual = _finite(row, RESIDUAL_KEY)
    if residual < 0.0:
        raise BadValue(
            RESIDUAL_KEY, f"must be >= 0 m/s (0: no perforation), got {row[RESIDUAL_KEY]!r}"
        )
    if residual > speed:
        raise BadValue(
            RESIDUAL_KEY,
            f"must not exceed the impact speed {speed:g} m/s, got {row[RESIDUAL_KEY]!r}",
        )
    exit_obliquity = _finite(row, EXIT_KEY)
    if not math.isnan(exit_obliquity) and not 0.0 <= exit_obliquity <= 180.0:
        raise BadValue(EXIT_KEY, f"must be in [0, 180] deg, got {row[EXIT_KEY]!r}")
    outcome = _outcome(row)
    perforated = _perforation(row, outcome, residual)
    weight = _finite(row, "weight")
    if weight < 0.0:
        raise BadValue("weight", f"must be >= 0, got {row['weight']!r}")
    note = row.get("source")
    return ShotRow(
        impact_speed=speed,
        impact_obliquity=obliquity,
        outcome=outcome,
        perforated=perforated,
        residual_speed=residual,
        exit_obliquity=exit_obliquity,
        radius=_in_range(row, RADIUS),
        mass=_in_range(row, MASS),
        weight=1.0 if math.isnan(weight) else weight,
        note="" if _is_blank(note) else str(note).strip(),
    )
