"""Input files as spreadsheets and editors write them: a UTF-8 byte-order mark, CRLF line
ends; and what is not UTF-8 at all, as one line."""

from __future__ import annotations

import numpy as np
import pytest
from test_output_files import assert_one_line, run_cli

import plateimpact as pi
from plateimpact_plugins import PstarTable

SHOTS = (
    "impact_speed_m_s,impact_obliquity_deg,residual_speed_m_s\r\n"
    "500,0,300\r\n700,0,520\r\n900,0,700\r\n300,0,0\r\n"
)
TABLE = (
    "obliquity_deg,ricochet_pstar_mm,perforation_pstar_mm,transition_start_m_s,transition_end_m_s"
    "\r\n0,4.6,4.6,300,330\r\n45,3.5,4.4,330,420\r\n"
)


def test_a_byte_order_mark_and_crlf_are_read_as_plain_text(tmp_path):
    plain, marked = tmp_path / "plain.csv", tmp_path / "marked.csv"
    plain.write_text(SHOTS.replace("\r\n", "\n"))
    marked.write_bytes(b"\xef\xbb\xbf" + SHOTS.encode())
    a, b = pi.Shots.from_csv(plain), pi.Shots.from_csv(marked)
    np.testing.assert_array_equal(a.impact_speed, b.impact_speed)
    np.testing.assert_array_equal(a.residual_speed, b.residual_speed)
    table = tmp_path / "table.csv"
    table.write_bytes(b"\xef\xbb\xbf" + TABLE.encode())
    assert PstarTable.from_csv(table).rows()[1] == pytest.approx((45.0, 3.5, 4.4, 330.0, 420.0))
    plate = tmp_path / "plate.json"
    pi.save_plate_file(plate, pi.presets.plate("2024-T3/3.18"))
    plate.write_bytes(b"\xef\xbb\xbf" + plate.read_bytes())
    assert pi.load_plate_file(plate) == pi.presets.plate("2024-T3/3.18")


def test_a_table_that_is_not_utf8_is_one_line(tmp_path):
    table = tmp_path / "table.csv"
    table.write_bytes(TABLE.encode("utf-16"))
    argv = ["run", "--preset", "SAE1010/1.47", "--speed", "500", "--obliquity", "45",
            "--failure", "variable-pstar", "--pstar-table", str(table)]  # fmt: skip
    code, _, err = run_cli(argv)
    assert_one_line(code, err, "--pstar-table", "not UTF-8")
    shots = tmp_path / "shots.csv"
    shots.write_bytes(SHOTS.encode("utf-16"))
    code, _, err = run_cli(["calibrate", str(shots), "--thickness", "3.18", "--pstar", "3",
                            "--alpha", "45"])  # fmt: skip
    assert_one_line(code, err, "not UTF-8")


def test_reproduce_onto_a_regular_file_is_one_line(tmp_path):
    taken = tmp_path / "report"
    taken.write_text("mine\n")
    code, _, err = run_cli(["reproduce", "--out", str(taken)])
    assert_one_line(code, err, "--out", "not a directory")
    assert taken.read_text() == "mine\n"
