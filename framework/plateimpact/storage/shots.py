"""Shot data: impact and residual speeds measured in firings, from a CSV file or columns.

A shot is one firing: impact speed [m/s], impact obliquity [deg] and residual speed [m/s]
(the speed after perforating; 0 when the sphere did not perforate), optionally the exit
obliquity [deg] and the outcome. The CSV header names the columns, in any order:

    impact_speed_m_s,impact_obliquity_deg,residual_speed_m_s[,exit_obliquity_deg][,outcome]

Lines starting with ``#`` are comments; other columns are ignored. Every bad value raises
:class:`~plateimpact.errors.ShotDataError` with one line naming the file, line, column and
value (and how many more rows are bad).
"""

from __future__ import annotations

import csv
import io
import math
import os
from collections.abc import Mapping, Sequence

import attrs
import numpy as np

from ..batch import SceneBatch
from ..bodies import Plate, Sphere
from ..errors import ShotDataError
from ..parameters import Parameter
from ..results import RESULT_FIELDS, Outcome
from ..scene import IMPACT_OBLIQUITY, IMPACT_SPEED
from ..simulation import Simulation
from ..units import deg

RESIDUAL_SPEED = Parameter(
    "residual_speed", "speed after perforating (0: the sphere did not perforate)", "m/s"
)
#: The CSV columns, named as the declarations of what they hold name them.
REQUIRED_COLUMNS = (IMPACT_SPEED.key, IMPACT_OBLIQUITY.key, RESIDUAL_SPEED.key)
OPTIONAL_COLUMNS = (RESULT_FIELDS["exit_obliquity"].key, "outcome")


@attrs.frozen(eq=False)
class Shots:
    """Shot data in SI units, one entry per shot.

    Attributes
    ----------
    impact_speed : numpy.ndarray
        Vs [m/s], in the range of :data:`~plateimpact.scene.IMPACT_SPEED`.
    impact_obliquity : numpy.ndarray
        θs [rad], in [0, π/2).
    residual_speed : numpy.ndarray
        Vr [m/s], in [0, Vs]; 0 means the sphere did not perforate.
    exit_obliquity : numpy.ndarray
        [rad], NaN where not recorded.
    outcome : numpy.ndarray
        :class:`~plateimpact.Outcome` values, 0 where not recorded.
    labels : tuple of str
        Where each shot came from (``shots.csv line 7``), for error messages.
    source : str
        The file (or ``"shots"``), for error messages about the whole set.
    """

    impact_speed: np.ndarray
    impact_obliquity: np.ndarray
    residual_speed: np.ndarray
    exit_obliquity: np.ndarray
    outcome: np.ndarray
    labels: tuple[str, ...]
    source: str = "shots"

    def __len__(self) -> int:
        return int(self.impact_speed.size)

    @property
    def perforated(self) -> np.ndarray:
        """Whether each shot perforated (residual speed > 0)."""
        return self.residual_speed > 0.0

    def take(self, index: np.ndarray) -> Shots:
        """The shots at ``index`` (a boolean mask or integer indices)."""
        kept = np.arange(len(self))[index]
        return Shots(
            self.impact_speed[kept],
            self.impact_obliquity[kept],
            self.residual_speed[kept],
            self.exit_obliquity[kept],
            self.outcome[kept],
            tuple(self.labels[i] for i in kept),
            self.source,
        )

    def normal_incidence(self) -> Shots:
        """The shots fired at obliquity 0 (the ones the report calibrates a and b on)."""
        return self.take(self.impact_obliquity == 0.0)

    @classmethod
    def from_columns(
        cls, columns: Mapping[str, Sequence[object]], *, source: str = "shots"
    ) -> Shots:
        """Shots from columns named as in the CSV header, in user units (m/s, deg).

        Values may be numbers or strings; empty optional values mean "not recorded".
        Errors name the row by index: ``shots row 3, column ...``.
        """
        lengths = {len(values) for values in columns.values()}
        if len(lengths) > 1:
            raise ShotDataError(f"{source}: columns differ in length: {sorted(lengths)}")
        count = lengths.pop() if lengths else 0
        _check_columns(source, list(columns))
        rows = [{name: columns[name][i] for name in columns} for i in range(count)]
        return _parse_rows(rows, [f"{source} row {i}" for i in range(count)], source)

    @classmethod
    def from_csv(cls, path: str | os.PathLike[str]) -> Shots:
        """Shots from a CSV file (see the module's description of the columns)."""
        source = os.fspath(path)
        try:
            with open(source, encoding="utf-8-sig", newline="") as handle:  # BOM allowed
                text = handle.read()
        except (OSError, UnicodeDecodeError) as exc:
            reason = exc.strerror if isinstance(exc, OSError) else "not UTF-8 text"
            raise ShotDataError(f"{source}: cannot read: {reason}") from None
        return cls.from_csv_text(text, source=source)

    @classmethod
    def from_csv_text(cls, text: str, *, source: str = "shots") -> Shots:
        """Shots from the text of a CSV file; ``source`` names it in error messages."""
        lines = [
            (number, line)
            for number, line in enumerate(text.splitlines(), start=1)
            if line.strip() and not line.lstrip().startswith("#")
        ]
        if not lines:
            raise ShotDataError(
                f"{source}: empty file, expected a header naming {', '.join(REQUIRED_COLUMNS)}"
            )
        records = list(csv.reader(line for _, line in lines))
        header = [name.strip() for name in records[0]]
        _check_columns(f"{source} line {lines[0][0]}", header)
        rows, labels = [], []
        for (number, _), record in zip(lines[1:], records[1:], strict=True):
            if len(record) != len(header):
                raise ShotDataError(
                    f"{source} line {number}: expected {len(header)} fields as in the "
                    f"header, got {len(record)}"
                )
            rows.append(dict(zip(header, record, strict=True)))
            labels.append(f"{source} line {number}")
        return _parse_rows(rows, labels, source)

    def to_csv_text(self, comments: Sequence[str] = ()) -> str:
        """The shots as CSV in user units, all five columns, ``# comment`` lines first."""
        buffer = io.StringIO()
        for comment in comments:
            buffer.write(f"# {comment}\n")
        writer = csv.writer(buffer, lineterminator="\n")
        writer.writerow(REQUIRED_COLUMNS + OPTIONAL_COLUMNS)
        for i in range(len(self)):
            exit_obliquity = self.exit_obliquity[i] / deg
            writer.writerow(
                [
                    f"{self.impact_speed[i]:.6g}",
                    f"{self.impact_obliquity[i] / deg:.6g}",
                    f"{self.residual_speed[i]:.6g}",
                    "" if math.isnan(exit_obliquity) else f"{exit_obliquity:.6g}",
                    Outcome(int(self.outcome[i])).label if self.outcome[i] else "",
                ]
            )
        return buffer.getvalue()


def _check_columns(where: str, names: Sequence[str]) -> None:
    duplicated = sorted({n for n in names if names.count(n) > 1})
    if duplicated:
        raise ShotDataError(f"{where}: column {duplicated[0]} appears more than once")
    missing = [c for c in REQUIRED_COLUMNS if c not in names]
    if missing:
        raise ShotDataError(
            f"{where}: missing column{'s' if len(missing) > 1 else ''} {', '.join(missing)} "
            f"(header has: {', '.join(names) or 'nothing'})"
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


def _check_row(row: Mapping[str, object]) -> tuple[list[float | int], tuple[str, str] | None]:
    """(values in user units, None) or (partial values, (column, problem)) for one row."""
    values: list[float | int] = []
    for column in REQUIRED_COLUMNS:
        raw = row[column]
        try:
            x = _number(raw)
        except (TypeError, ValueError):
            return values, (column, f"not a number, got {raw!r}")
        if not math.isfinite(x):
            return values, (column, f"must be finite, got {raw!r}")
        values.append(x)
    speed, obliquity, residual = values
    if not IMPACT_SPEED.range.contains(speed):
        allowed = IMPACT_SPEED.describe_range()
        return values, ("impact_speed_m_s", f"must be {allowed}, got {row['impact_speed_m_s']!r}")
    if not 0.0 <= obliquity < 90.0:
        return values, (
            "impact_obliquity_deg",
            f"must be in [0, 90) deg, got {row['impact_obliquity_deg']!r}",
        )
    if residual < 0.0:
        return values, (
            "residual_speed_m_s",
            f"must be >= 0 m/s (0: no perforation), got {row['residual_speed_m_s']!r}",
        )
    if residual > speed:
        return values, (
            "residual_speed_m_s",
            f"must not exceed the impact speed {speed:g} m/s, got {row['residual_speed_m_s']!r}",
        )
    exit_obliquity = math.nan
    raw = row.get("exit_obliquity_deg")
    if not _is_blank(raw):
        try:
            exit_obliquity = _number(raw)
        except (TypeError, ValueError):
            return values, ("exit_obliquity_deg", f"not a number, got {raw!r}")
        if not 0.0 <= exit_obliquity <= 180.0:
            return values, ("exit_obliquity_deg", f"must be in [0, 180] deg, got {raw!r}")
    outcome = 0
    raw = row.get("outcome")
    if not _is_blank(raw):
        names = {o.label: o for o in Outcome}
        label = str(raw).strip().lower()
        if label not in names:
            return values, ("outcome", f"must be one of {', '.join(names)}, got {raw!r}")
        outcome = int(names[label])
        # The residual speed is the speed through the plate: only a perforation has one.
        if (outcome == Outcome.PERFORATION) != (residual > 0.0):
            return values, (
                "outcome",
                f"{label} contradicts residual speed {residual:g} m/s "
                "(only a perforation has a residual speed > 0)",
            )
    return [speed, obliquity, residual, exit_obliquity, outcome], None


def _parse_rows(rows: Sequence[Mapping[str, object]], labels: list[str], source: str) -> Shots:
    if not rows:
        raise ShotDataError(f"{source}: no shots after the header")
    parsed, problems = [], []
    for label, row in zip(labels, rows, strict=True):
        values, problem = _check_row(row)
        if problem is None:
            parsed.append(values)
        else:
            problems.append(f"{label}, column {problem[0]}: {problem[1]}")
    if problems:
        more = f" (and {len(problems) - 1} more bad rows)" if len(problems) > 1 else ""
        raise ShotDataError(problems[0] + more)
    table = np.array(parsed, dtype=float).T
    return Shots(
        impact_speed=table[0],
        impact_obliquity=table[1] * deg,
        residual_speed=table[2],
        exit_obliquity=table[3] * deg,
        outcome=table[4].astype(int),
        labels=tuple(labels),
        source=source,
    )


def synthetic_shots(
    plate: Plate,
    sphere: Sphere,
    impact_speeds: Sequence[float] | np.ndarray,
    *,
    noise: float = 0.0,
    seed: int | None = None,
    simulation: Simulation | None = None,
) -> Shots:
    """Shots at normal incidence made by the model itself, with optional noise.

    The residual speeds are the model's for ``plate`` and ``sphere`` at
    ``impact_speeds`` [m/s] (one batch), each multiplied by ``1 + noise * N(0, 1)``
    (``noise`` is the relative standard deviation, e.g. 0.02; a perforation stays a
    perforation: the factor is kept above 0.1). For testing a calibration against known
    constants, never as a substitute for firings.
    """
    speeds = np.asarray(impact_speeds, dtype=float).reshape(-1)
    simulation = simulation or Simulation.from_names()
    result = simulation.run_batch(SceneBatch.grid(sphere, plate, speeds, np.zeros(1)))
    factor = 1.0 + noise * np.random.default_rng(seed).standard_normal(speeds.size)
    residual = result.exit_speed * np.maximum(factor, 0.1)
    perforated = result.outcome == Outcome.PERFORATION
    return Shots(
        impact_speed=speeds,
        impact_obliquity=np.zeros(speeds.size),
        residual_speed=np.where(perforated, np.minimum(residual, speeds), 0.0),
        exit_obliquity=np.where(perforated, result.exit_obliquity, np.nan),
        outcome=result.outcome.astype(int),
        labels=tuple(f"synthetic shot {i}" for i in range(speeds.size)),
        source="synthetic shots",
    )
