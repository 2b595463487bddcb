"""Shot rows read one at a time (for :mod:`.shots`): a CSV file is parsed as it is read,
each row checked as it comes (:mod:`.shot_rows`) and kept in compact columns, so that the
first bad row is reported at once and memory grows by some 80 bytes a shot, whatever the
file holds (docs/calibration.md, "1. Shot data").

Bounds: at most :data:`MAX_SHOTS` shots and lines of at most :data:`MAX_LINE_CHARS`
characters; after the first bad row, at most :data:`MORE_ROWS_CHECKED` more rows are
read, to say how many more are bad, and the rest of the file is not read.
"""

from __future__ import annotations

import csv
from array import array
from collections.abc import Iterable, Iterator, Mapping, Sequence
from typing import TextIO, overload

import numpy as np

from ..base.errors import ShotDataError
from .shot_rows import (
    PERFORATION_COLUMNS,
    REQUIRED_COLUMNS,
    BadValue,
    ShotRow,
    check_columns,
    check_row,
)

#: The most shots a file (or columns) may hold: a test series is tens to thousands of
#: shots; a million is already more than any range fires, and each shot is a scene for
#: validate and the fits.
MAX_SHOTS = 1_000_000
#: After the first bad row, how many more rows are checked to count the bad ones.
MORE_ROWS_CHECKED = 10_000
#: The longest line read [characters]: a row is some 100; a longer line is no shot file.
MAX_LINE_CHARS = 65_536

_FLOAT_COLUMNS = (
    "impact_speed",
    "impact_obliquity",
    "residual_speed",
    "exit_obliquity",
    "radius",
    "mass",
    "weight",
)


class ShotLabels(Sequence[str]):
    """Where each shot came from (``shots.csv line 7``), made when asked: a prefix and one
    line (or row) number per shot, 8 bytes a shot rather than a string."""

    def __init__(self, prefix: str, numbers: np.ndarray, word: str = "line") -> None:
        self.prefix, self.word = prefix, word
        self.numbers = np.asarray(numbers, dtype=np.int64)

    def __len__(self) -> int:
        return int(self.numbers.size)

    @overload
    def __getitem__(self, index: int) -> str: ...

    @overload
    def __getitem__(self, index: slice) -> ShotLabels: ...

    def __getitem__(self, index: int | slice) -> str | ShotLabels:
        if isinstance(index, slice):
            return ShotLabels(self.prefix, self.numbers[index], self.word)
        return f"{self.prefix} {self.word} {int(self.numbers[index])}"

    def __iter__(self) -> Iterator[str]:
        return (f"{self.prefix} {self.word} {int(n)}" for n in self.numbers)

    def take(self, index: np.ndarray) -> ShotLabels:
        """The labels at ``index`` (integer indices)."""
        return ShotLabels(self.prefix, self.numbers[index], self.word)

    def __eq__(self, other: object) -> bool:
        if not isinstance(other, Sequence) or isinstance(other, str):
            return NotImplemented
        return len(self) == len(other) and all(a == b for a, b in zip(self, other, strict=True))

    __hash__ = None  # type: ignore[assignment]  # mutable-looking, like a list

    def __repr__(self) -> str:
        return f"ShotLabels({self.prefix!r}, {len(self)} {self.word}s)"


class ShotColumns:
    """Checked rows kept column by column in user units: doubles, bytes and line numbers
    in :class:`array.array` (no object per row); notes interned."""

    def __init__(self) -> None:
        self.floats = {name: array("d") for name in _FLOAT_COLUMNS}
        self.outcome, self.perforated = array("b"), array("b")
        self.numbers = array("q")
        self.notes: list[str] = []
        self._interned: dict[str, str] = {}

    def __len__(self) -> int:
        return len(self.numbers)

    def add(self, row: ShotRow, number: int) -> None:
        for name, column in self.floats.items():
            column.append(getattr(row, name))
        self.outcome.append(row.outcome)
        self.perforated.append(row.perforated)
        self.numbers.append(number)
        self.notes.append(self._interned.setdefault(row.note, row.note))

    def arrays(self) -> dict[str, np.ndarray]:
        """Each column as a numpy array (user units; NaN where not given)."""
        # views of the arrays' own buffers, not copies
        out = {name: np.frombuffer(column, dtype=float) for name, column in self.floats.items()}
        out["outcome"] = np.array(self.outcome, dtype=int)
        out["perforated"] = np.array(self.perforated, dtype=bool)
        return out


def check_count(source: str, count: int) -> None:
    """:class:`ShotDataError` for more than MAX_SHOTS shots."""
    if count > MAX_SHOTS:
        raise ShotDataError(
            f"{source}: {count:,} shots, more than the {MAX_SHOTS:,} a shot set may hold (split it)"
        )


def check_all(
    records: Iterable[tuple[int, Mapping[str, object] | str]], source: str, word: str
) -> ShotColumns:
    """Every row of ``records`` (its number and its cells, or what is wrong with its
    shape) checked and kept; :class:`ShotDataError` naming the first bad row, and how
    many of at most MORE_ROWS_CHECKED rows after it are bad, as soon as that is known."""
    columns = ShotColumns()
    first: str | None = None
    more = after = 0
    complete = True
    for number, row in records:
        if first is not None and after == MORE_ROWS_CHECKED:
            complete = False
            break
        try:
            if isinstance(row, str):
                raise BadValue("", row)
            checked = check_row(row)
        except BadValue as bad:
            if first is None:
                column = f", column {bad.column}" if bad.column else ""
                first = f"{source} {word} {number}{column}: {bad.problem}"
            else:
                more += 1
                after += 1
            continue
        if first is not None:
            after += 1
        elif len(columns) == MAX_SHOTS:
            raise ShotDataError(
                f"{source} {word} {number}: more than {MAX_SHOTS:,} shots, the most a shot "
                "set may hold (split the file)"
            )
        else:
            columns.add(checked, number)
    if first is not None:
        if not complete:
            counted = f"and {more} more bad rows" if more else "no other bad row"
            first += f" ({counted} in the next {MORE_ROWS_CHECKED:,}; the rest not read)"
        elif more:
            first += f" (and {more} more bad rows)"
        raise ShotDataError(first)
    if not len(columns):
        raise ShotDataError(f"{source}: no shots after the header")
    return columns


def csv_records(handle: TextIO, source: str) -> Iterator[tuple[int, Mapping[str, object] | str]]:
    """The rows of a CSV file as they are read: (line number, cells by column name), or
    (line number, what is wrong) for a row of the wrong length. Comment lines (``#``)
    and blank lines are skipped; the header is checked first (:func:`check_columns`)."""
    pending: list[int] = []  # the numbers of the lines the csv reader has taken

    def lines() -> Iterator[str]:
        number = 0
        while line := handle.readline(MAX_LINE_CHARS + 1):
            number += 1
            if len(line) > MAX_LINE_CHARS:
                raise ShotDataError(
                    f"{source} line {number}: longer than {MAX_LINE_CHARS:,} characters "
                    "(no shot file has such lines)"
                )
            if line.strip() and not line.lstrip().startswith("#"):
                pending.append(number)
                yield line

    reader = csv.reader(lines())
    header: list[str] | None = None
    while True:
        try:
            record = next(reader)
        except StopIteration:
            break
        except csv.Error as exc:
            where = f" line {pending[0]}" if pending else ""
            raise ShotDataError(f"{source}{where}: not CSV: {exc}") from None
        number = pending[0]
        pending.clear()
        if header is None:
            header = [name.strip() for name in record]
            check_columns(f"{source} line {number}", header)
            continue
        if len(record) != len(header):
            yield number, f"expected {len(header)} fields as in the header, got {len(record)}"
        else:
            yield number, dict(zip(header, record, strict=True))
    if header is None:
        raise ShotDataError(
            f"{source}: empty file, expected a header naming {', '.join(REQUIRED_COLUMNS)} "
            f"and one of {', '.join(PERFORATION_COLUMNS)}"
        )


def column_records(
    columns: Mapping[str, Sequence[object]],
) -> Iterator[tuple[int, Mapping[str, object]]]:
    """The rows of columns given in Python, numbered from 0."""
    count = len(next(iter(columns.values()))) if columns else 0
    for i in range(count):
        yield i, {name: values[i] for name, values in columns.items()}
