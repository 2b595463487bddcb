"""The report's variable-P* table (Figures 38–44): P* by impact obliquity and speed, its
file format (:data:`TABLE_COLUMNS`) and the report's values for SAE 1010.

The ``variable-pstar`` failure model reads a table as its setting; the report's
calibration (``plateimpact calibrate --fit pstar --by-obliquity``) writes one.
"""

from __future__ import annotations

import csv
import io
import math
import os
from collections.abc import Sequence
from typing import final

import attrs
import numpy as np

from plateimpact import Parameter, ParameterError, check_input

from .constants import CRITICAL_PENETRATION

#: The smallest P* of a row [mm]: the plate constant's.
SMALLEST_PSTAR_MM = CRITICAL_PENETRATION.range.low / CRITICAL_PENETRATION.scale

#: Rows a table takes at most: a row per obliquity measured, a few in practice; and the
#: largest table file read [bytes] (1000 rows of five long numbers).
MAX_ROWS = 1000
MAX_BYTES = 1 << 20

TABLE_COLUMNS = (
    "obliquity_deg",
    "ricochet_pstar_mm",
    "perforation_pstar_mm",
    "transition_start_m_s",
    "transition_end_m_s",
)


def _fail(message: str) -> ParameterError:
    return ParameterError("table", f"pstar table: {message}")


@final
@attrs.frozen(eq=False)
class PstarTable:
    """P* as a function of impact obliquity and impact speed, from a few rows.

    Each row gives, at one impact obliquity, the P* that fits the ricochet range, the P*
    that fits the perforation range, and the band of impact speeds over which one turns
    into the other. Between rows every column is interpolated linearly in obliquity;
    outside the rows the nearest row holds. At the scene's obliquity, P* is the ricochet
    value below the band, the perforation value above it, linear inside it.

    Attributes are SI arrays: obliquity [rad] (strictly increasing), ricochet and
    perforation [m] (>= 1e-9, as P*), transition_start <= transition_end [m/s] (>= 0). Build one in
    user units with :meth:`from_rows` or :meth:`from_csv`.
    """

    obliquity: np.ndarray
    ricochet: np.ndarray
    perforation: np.ndarray
    transition_start: np.ndarray
    transition_end: np.ndarray

    @classmethod
    def from_rows(cls, rows: Sequence[Sequence[float | str]]) -> PstarTable:
        """Rows of (obliquity [deg], ricochet P* [mm], perforation P* [mm], transition
        start [m/s], transition end [m/s]), sorted by obliquity."""
        if len(rows) == 0:
            raise _fail("needs at least one row")
        if len(rows) > MAX_ROWS:
            raise _fail(f"{len(rows):,} rows; a table takes at most {MAX_ROWS:,}")
        values = []
        for number, row in enumerate(rows, start=1):
            if len(row) != len(TABLE_COLUMNS):
                raise _fail(f"row {number} has {len(row)} values, expected {len(TABLE_COLUMNS)}")
            try:
                values.append([float(x) for x in row])
            except (TypeError, ValueError):
                shown = f"{row!r:.80}"  # repr: control characters escaped
                raise _fail(f"row {number} has a value that is not a number: {shown}") from None
        data = np.array(values)
        for number, (obliquity, ricochet, perforation, start, end) in enumerate(data, start=1):
            if not 0.0 <= obliquity < 90.0:
                raise _fail(f"row {number}: obliquity_deg must be in [0, 90), got {obliquity:g}")
            for name, value in (
                ("ricochet_pstar_mm", ricochet),
                ("perforation_pstar_mm", perforation),
            ):
                if not (math.isfinite(value) and value >= SMALLEST_PSTAR_MM):
                    raise _fail(
                        f"row {number}: {name} must be finite and >= {SMALLEST_PSTAR_MM:g} mm, "
                        f"got {value:g}"
                    )
            if not (math.isfinite(start) and math.isfinite(end) and 0.0 <= start <= end):
                raise _fail(
                    f"row {number}: transition speeds must satisfy 0 <= start <= end m/s, "
                    f"got {start:g} and {end:g}"
                )
        steps = np.diff(data[:, 0])
        if np.any(steps <= 0.0):
            k = int(np.flatnonzero(steps <= 0.0)[0])
            raise _fail(
                f"obliquity_deg must be strictly increasing, got {data[k + 1, 0]:g} after "
                f"{data[k, 0]:g} (row {k + 2})"
            )
        return cls(
            np.radians(data[:, 0]), data[:, 1] * 1e-3, data[:, 2] * 1e-3, data[:, 3], data[:, 4]
        )

    @classmethod
    def from_csv(cls, path: str | os.PathLike[str]) -> PstarTable:
        """A table from a CSV file with the header of :data:`TABLE_COLUMNS` (any order)."""
        where = f"{os.fspath(path)!r:.200}"  # repr: control characters escaped
        check_input(path, where, _fail)
        try:
            with open(path, "rb") as handle:  # never more than a table can hold
                data = handle.read(MAX_BYTES + 1)
            if len(data) > MAX_BYTES:
                raise _fail(f"{where}: more than {MAX_BYTES:,} bytes; a table holds at most that")
            reader = csv.DictReader(io.StringIO(data.decode("utf-8-sig"), newline=""))
            names = [name.strip() for name in reader.fieldnames or ()]
            missing = set(TABLE_COLUMNS) - set(names)
            if missing:
                raise _fail(f"{where}: missing columns {', '.join(sorted(missing))}")
            reader.fieldnames = names
            rows = [[line[c] for c in TABLE_COLUMNS] for line in reader]
        except OSError as exc:
            raise _fail(f"cannot read {where}: {exc.strerror}") from None
        except UnicodeDecodeError:
            raise _fail(f"cannot read {where}: not UTF-8 text") from None
        except csv.Error as exc:
            raise _fail(f"{where}: not a CSV table ({str(exc)!r:.80})") from None
        return cls.from_rows(rows)

    @classmethod
    def constant(cls, pstar: float) -> PstarTable:
        """One P* [m] for every impact."""
        return cls.from_rows([(0.0, pstar * 1e3, pstar * 1e3, 0.0, 0.0)])

    def as_setting(self) -> list[list[float]]:
        """The table as a JSON value (its rows, plain floats), for study variants and
        archives."""
        return [[float(x) for x in row] for row in self.rows()]

    def rows(self) -> list[tuple[float, ...]]:
        """The table in user units, as :meth:`from_rows` takes it."""
        return [
            (math.degrees(o), r * 1e3, p * 1e3, s, e)
            for o, r, p, s, e in zip(
                self.obliquity,
                self.ricochet,
                self.perforation,
                self.transition_start,
                self.transition_end,
                strict=True,
            )
        ]

    def __call__(self, obliquity: np.ndarray, speed: np.ndarray) -> np.ndarray:
        """P* [m] for impact obliquity [rad] and impact speed [m/s] (arrays)."""
        column = lambda values: np.interp(obliquity, self.obliquity, values)  # noqa: E731
        ricochet, perforation = column(self.ricochet), column(self.perforation)
        start, end = column(self.transition_start), column(self.transition_end)
        width = end - start
        inside = np.divide(
            speed - start, width, out=(speed >= start).astype(float), where=width > 0
        )
        # ricochet + w (perforation − ricochet) is exactly the ricochet value when the two
        # are equal, so a constant table reproduces constant P* to the last bit.
        return ricochet + np.clip(inside, 0.0, 1.0) * (perforation - ricochet)


#: The report's values for SAE 1010 (Figures 38–44): 4.6 mm at normal incidence; at 45°,
#: 3.5 mm fits the ricochet data and 4.4 mm the perforation data; at 60°, 3.0 and 3.8 mm.
#: Each transition band runs from the last ricochet predicted with the ricochet-range P*
#: to the first perforation predicted with the perforation-range P* (docs/variable-pstar.md),
#: so that ricochet-range impacts get exactly the first value and perforation-range impacts
#: exactly the second. At 0° the band only shapes the interpolation toward 45°.
SAE1010_TABLE = PstarTable.from_rows(
    [
        (0.0, 4.6, 4.6, 300.0, 330.0),
        (45.0, 3.5, 4.4, 330.0, 420.0),
        (60.0, 3.0, 3.8, 430.0, 550.0),
    ]
)


def _to_table(value: object) -> PstarTable:
    if isinstance(value, PstarTable):
        return value
    if isinstance(value, str | os.PathLike):
        return PstarTable.from_csv(value)
    if isinstance(value, Sequence):
        return PstarTable.from_rows(value)
    raise ParameterError(
        "table", f"pstar table must be a PstarTable, rows or a CSV path, got {value!r}"
    )


def _table_json(value: object) -> object:
    """The table as a JSON value: its rows. What an archive gives back is already rows
    (plain lists): checked as rows and kept as they are, so a setting read back describes
    itself exactly as the table did (converting them through SI again could move the
    last digit). A CSV path stays the path it is."""
    if isinstance(value, PstarTable):
        return value.as_setting()
    if isinstance(value, str | os.PathLike):
        return os.fspath(value)
    _to_table(value)  # a ParameterError for what no table is made of
    rows: Sequence[Sequence[float]] = value if isinstance(value, Sequence) else ()
    return [[float(x) for x in row] for row in rows]


PSTAR_TABLE = Parameter(
    "table",
    "P* by impact obliquity and speed: a PstarTable, its rows, or a CSV file with columns "
    + ",".join(TABLE_COLUMNS)
    + " (none: the report's SAE 1010 values)",
    default=None,
    flag="--pstar-table",
    convert=lambda value: _to_table(SAE1010_TABLE if value is None else value),
    to_json=_table_json,
)
