"""Shot files are read a row at a time: the first bad row is reported without reading
the rest of the file, memory grows by a bounded number of bytes a shot, and a file of
more shots than a set may hold is refused where it passes the bound (docs/calibration.md,
"1. Shot data"; docs/robustness.md, "The input domain and the work bounds").

"Without reading the rest" is shown, not timed: the rest of each file ends in bytes that
are not UTF-8, which a reader that got there would report instead (MARGIN rows before
them: text is decoded 8 KB ahead of the line read).
"""

from __future__ import annotations

import tracemalloc

import numpy as np
import pytest
from test_output_files import assert_one_line, run_cli

import plateimpact as pi
from plateimpact.storage import shot_reader
from plateimpact.storage.shot_reader import MAX_LINE_CHARS, MORE_ROWS_CHECKED, ShotLabels

HEADER = "impact_speed_m_s,impact_obliquity_deg,outcome,residual_speed_m_s\n"
GOOD = "612.5,45,perforation,130.25\n"
NOT_UTF8 = b"\xff\xfe not text\n"
MARGIN = GOOD * 1000  # 28 KB


def write(path, *parts: str | bytes) -> str:
    path.write_bytes(b"".join(p if isinstance(p, bytes) else p.encode() for p in parts))
    return str(path)


def test_a_bad_second_line_is_reported_without_reading_the_rest(tmp_path):
    path = write(tmp_path / "s.csv", HEADER, "fast,45,perforation,130\n",
                 GOOD * MORE_ROWS_CHECKED, MARGIN, NOT_UTF8)  # fmt: skip
    with pytest.raises(pi.ShotDataError) as caught:
        pi.Shots.from_csv(path)
    assert str(caught.value) == (
        f"{path} line 2, column impact_speed_m_s: not a number, got 'fast' (no other bad "
        "row in the next 10,000; the rest not read)"
    )


def test_bad_rows_after_the_first_are_counted_within_the_next_ten_thousand(tmp_path):
    bad = "500,95,perforation,100\n"  # obliquity out of range
    rows = [GOOD] * MORE_ROWS_CHECKED
    rows[10] = rows[500] = rows[MORE_ROWS_CHECKED - 1] = bad  # 3 more, the last at the edge
    path = write(tmp_path / "s.csv", HEADER, GOOD, bad, *rows, bad, MARGIN, NOT_UTF8)
    with pytest.raises(pi.ShotDataError) as caught:
        pi.Shots.from_csv(path)
    message = str(caught.value)
    assert message.startswith(f"{path} line 3, column impact_obliquity_deg: must be in [0, 90)")
    assert message.endswith("(and 3 more bad rows in the next 10,000; the rest not read)")
    # a file that ends within the next 10,000 rows is counted whole, as before
    path = write(tmp_path / "t.csv", HEADER, bad, GOOD, bad, ",45,,\n", "x,1,2\n")
    with pytest.raises(pi.ShotDataError, match=r"line 2, .* \(and 3 more bad rows\)$"):
        pi.Shots.from_csv(path)


def test_more_shots_than_a_set_holds_are_refused_where_the_bound_is_passed(tmp_path, monkeypatch):
    monkeypatch.setattr(shot_reader, "MAX_SHOTS", 100)
    path = write(tmp_path / "s.csv", "# a comment\n", HEADER, GOOD * 101, MARGIN, NOT_UTF8)
    with pytest.raises(pi.ShotDataError) as caught:
        pi.Shots.from_csv(path)
    assert str(caught.value) == (
        f"{path} line 103: more than 100 shots, the most a shot set may hold (split the file)"
    )
    assert len(pi.Shots.from_csv(write(tmp_path / "t.csv", HEADER, GOOD * 100))) == 100
    columns = {"impact_speed_m_s": [500.0] * 101, "impact_obliquity_deg": [0.0] * 101,
               "perforated": [1] * 101}  # fmt: skip
    with pytest.raises(pi.ShotDataError, match="101 shots, more than the 100"):
        pi.Shots.from_columns(columns)
    blank = np.full(101, np.nan)
    with pytest.raises(pi.ShotDataError, match="101 shots, more than the 100"):
        pi.Shots(blank + 500, blank * 0, blank, blank, np.zeros(101, int), ("x",) * 101)


def test_memory_grows_by_a_bounded_number_of_bytes_a_shot(tmp_path):
    """20,000 shots: columns of doubles, not a list of dicts of strings. The bound, 300
    bytes a shot, is the columns (7 doubles, 2 bytes, a line number, a note reference:
    75 bytes) with their SI copies and room for the row being parsed (measured: 137);
    the file itself is 28 bytes a shot, and the old reader, holding its text, lines and
    dicts, took 1,076."""
    count = 20_000
    path = write(tmp_path / "s.csv", HEADER, GOOD * count)
    tracemalloc.start()
    try:
        shots = pi.Shots.from_csv(path)
        peak = tracemalloc.get_traced_memory()[1]
    finally:
        tracemalloc.stop()
    assert len(shots) == count and shots.labels[-1] == f"{path} line {count + 1}"
    assert peak < 300 * count, peak / count


def test_a_line_longer_than_any_shot_file_has_is_one_line(tmp_path):
    path = write(
        tmp_path / "s.csv", HEADER, GOOD, "7" * (MAX_LINE_CHARS + 1), "\n", MARGIN, NOT_UTF8
    )
    code, _, err = run_cli(["validate", path, "--preset", "2024-T3/1.27"])
    assert_one_line(code, err, f"{path} line 3: longer than 65,536 characters")


def test_a_field_the_csv_module_refuses_is_one_line(tmp_path):
    """A quote left open swallows every line after it into one field, until the csv
    module's field limit (131,072 characters) stops it."""
    path = write(tmp_path / "s.csv", HEADER, GOOD, '"500', ",45\n" * 50_000)
    with pytest.raises(pi.ShotDataError, match=r"^.*s\.csv line 3: not CSV: field larger than"):
        pi.Shots.from_csv(path)


def test_labels_are_made_when_asked_and_behave_as_the_tuple_they_replace():
    labels = ShotLabels("s.csv", np.array([2, 5, 9]))
    as_tuple = ("s.csv line 2", "s.csv line 5", "s.csv line 9")
    assert labels == as_tuple and list(labels) == list(as_tuple) and len(labels) == 3
    assert labels[1] == "s.csv line 5" and labels[-1] == "s.csv line 9"
    assert labels[1:] == as_tuple[1:] and labels.take(np.array([2, 0])) == as_tuple[2::-2]
    assert labels != as_tuple[:2] and ShotLabels("shots", np.array([0]), "row") == ("shots row 0",)
