"""``plateimpact limits`` and ``plateimpact map``: the JSON contract of issue 16, CSV,
figures, and bad input as one line and exit 2 with nothing written."""

from __future__ import annotations

import csv
import io
import json
import math

import numpy as np
import pytest
from test_output_files import assert_one_line, run_cli

import plateimpact as pi
from plateimpact import limits, presets

PLATE = ["--preset", "2024-T3/3.18"]
ALONG_SPEED = ["limits", *PLATE, "--obliquities", "0,45", "--speeds", "100:900"]
ALONG_OBLIQUITY = ["limits", *PLATE, "--speeds", "600", "--obliquities", "30:80"]


def test_limits_json_follows_the_contract_and_is_the_apis_result():
    code, out, err = run_cli([*ALONG_SPEED, "--tolerance", "0.05", "--json"])
    assert code == 0, err
    found = json.loads(out)
    assert {"plate", "sphere", "model", "tolerance_m_s", "lines"} <= set(found)
    assert found["tolerance_m_s"] == 0.05 and found["resolution_m_s"] == 1.0
    assert found["plate"]["thickness_mm"] == 3.18 and found["sphere"]["radius_mm"] == 3.175
    assert found["model"]["failure"] == "plugging" and "integrator_settings" in found["model"]
    api = limits.along_speed(
        pi.Simulation.from_names(), presets.DEFAULT_SPHERE, presets.plate("2024-T3/3.18"),
        np.radians([0.0, 45.0]), (100.0, 900.0), tolerance=0.05,
    )  # fmt: skip
    assert [line["obliquity_deg"] for line in found["lines"]] == [0.0, 45.0]
    for line, expected in zip(found["lines"], api.lines, strict=True):
        bands = line["bands"]
        assert bands[0]["from_m_s"] == 100.0 and bands[-1]["to_m_s"] == 900.0
        assert all(a["to_m_s"] == b["from_m_s"] for a, b in zip(bands[:-1], bands[1:], strict=True))
        assert {b["outcome"] for b in bands} <= {"ricochet", "embedment", "perforation"}
        assert [(b["outcome"], b["plate_failed"]) for b in bands] == [
            (b.regime.outcome.label, b.regime.plate_failed) for b in expected.bands
        ]
        assert [b["to_m_s"] for b in bands] == [b.end for b in expected.bands]
        assert line["ballistic_limit_m_s"] == expected.ballistic_limit
        assert line["ricochet_limit_m_s"] == expected.ricochet_limit
    assert found["lines"][0]["ricochet_limit_m_s"] is None  # no ricochet at normal incidence


def test_limits_along_obliquity_names_its_keys_in_degrees():
    code, out, err = run_cli([*ALONG_OBLIQUITY, "--json"])
    assert code == 0, err
    (line,) = json.loads(out)["lines"]
    assert line["speed_m_s"] == 600.0
    assert line["bands"][0]["from_deg"] == 30.0 and line["bands"][-1]["to_deg"] == 80.0
    critical = line["critical_ricochet_obliquity_deg"]
    assert line["bands"][-1]["outcome"] == "ricochet" and 30.0 < critical < 80.0
    assert json.loads(out)["tolerance_deg"] == pytest.approx(0.001)


def test_limits_text_csv_and_png(tmp_path):
    table, drawing = tmp_path / "bands.csv", tmp_path / "bands.png"
    code, out, err = run_cli([*ALONG_SPEED, "--csv", str(table), "--png", str(drawing)])
    assert code == 0, err
    first, second, summary = out.splitlines()
    assert first.startswith("2024-T3/3.18 at 0 deg: embedment 100.00-")
    assert "ballistic limit" in second and "ricochet limit" in second
    assert summary.startswith("boundaries bracketed to 0.01 m/s, no band of 1 m/s missed")
    rows = list(csv.DictReader(io.StringIO(table.read_text())))
    assert list(rows[0]) == ["obliquity_deg", "outcome", "plate_failed", "from_m_s", "to_m_s"]
    assert {row["obliquity_deg"] for row in rows} == {"0.0", "45.0"}
    assert drawing.read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"
    code, out, _ = run_cli([*ALONG_SPEED, "--outcome", "perforation"])
    assert out.splitlines()[0].split(": ")[1].startswith("perforation ")


@pytest.mark.parametrize(
    ("argv", "named"),
    [
        ([*ALONG_SPEED[:-1], "500:500"], "--speeds: the range is empty"),
        ([*ALONG_SPEED[:-1], "900:100"], "--speeds: the range is empty"),
        ([*ALONG_SPEED, "--tolerance", "0"], "--tolerance: tolerance must be in [9e-11, 800] m/s"),
        ([*ALONG_SPEED, "--tolerance", "-1"], "--tolerance: tolerance must be in"),
        ([*ALONG_SPEED, "--tolerance", "5000"], "--tolerance: tolerance must be in"),
        (
            [*ALONG_SPEED, "--tolerance", "nan"],
            "--tolerance: tolerance must be in [9e-11, 800] m/s",
        ),
        ([*ALONG_SPEED, "--resolution", "0.001"], "--resolution: resolution must be in [0.01,"),
        ([*ALONG_SPEED, "--resolution", "1e-6", "--tolerance", "1e-6"], "--resolution: "),
        ([*ALONG_SPEED, "--outcome", "bounce"], "--outcome must be one of ricochet, embedment"),
        ([*ALONG_SPEED[:-3], "95", "--speeds", "100:900"], "--obliquities: impact_obliquity"),
        ([*ALONG_SPEED[:-1], "100:2e4"], "--speeds: impact_speed must be in"),
        (["limits", *PLATE, "--speeds", "100:900"], "give --obliquities as lines"),
        (["limits", *PLATE, "--obliquities", "0,45", "--speeds", "300,600"], "--speeds must be a"),
        ([*ALONG_OBLIQUITY[:-1], "0:95"], "--obliquities: impact_obliquity must be in"),
        (
            [*ALONG_OBLIQUITY, "--tolerance", "100"],
            "--tolerance: tolerance must be in [8e-12, 50] deg",
        ),
        (["map", *PLATE, "--speeds", "50:2000"], "--speeds must be START:STOP:N"),
        (["map", *PLATE, "--speeds", "50:2000:1"], "--speeds: a map needs at least 2 speeds"),
        (["map", *PLATE, "--obliquities", "30,10"], "--obliquities: the map's obliquities"),
        (["map", *PLATE, "--tolerance", "50"], "--tolerance: tolerance must be in [2e-10, 9.79"),
    ],
)
def test_bad_limits_and_maps_are_one_line_and_write_nothing(argv, named, tmp_path):
    out = ["--png", str(tmp_path / "x.png")]
    code, _, err = run_cli(
        [*argv, *out] if argv[0] == "map" else [*argv, "--csv", str(tmp_path / "x.csv")]
    )
    assert_one_line(code, err, named)
    assert list(tmp_path.iterdir()) == []


def test_map_draws_outcomes_and_limit_curves(tmp_path):
    # a coarse tolerance: what is checked is the drawing's, not where the limits lie
    small = ["--speeds", "100:900:40", "--obliquities", "0:60:7", "--tolerance", "5"]
    drawing = tmp_path / "map.png"
    code, out, err = run_cli(["map", *PLATE, *small, "--png", str(drawing)])
    assert code == 0, err
    assert out.splitlines()[0].startswith("2024-T3/3.18: 1 map(s) of 7 x 40, ")
    assert drawing.read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"
    curves = tmp_path / "curves.svg"
    argv = ["map", "--kind", "limits", *PLATE, "--preset", "2024-T3/6.35", *small,
            "--png", str(curves)]  # fmt: skip
    code, out, err = run_cli(argv)
    assert code == 0, err
    assert out.startswith("2024-T3/3.18, 2024-T3/6.35: 2 map(s) of 7 x 40, ")
    assert "ballistic limit" in curves.read_text()


def test_map_csv_and_json_give_every_cell_of_every_map_in_user_units(tmp_path):
    small = ["--speeds", "100:1500:5", "--obliquities", "0,45", "--tolerance", "5"]
    cells = tmp_path / "cells.csv"
    argv = ["map", *PLATE, "--preset", "2024-T3/6.35", *small, "--csv", str(cells), "--json"]
    code, out, err = run_cli(argv)
    assert code == 0, err
    maps = json.loads(out)["maps"]  # --json: the one object is all that is printed
    assert [m["preset"] for m in maps] == ["2024-T3/3.18", "2024-T3/6.35"]
    assert maps[0]["impact_speed_m_s"] == [100.0, 450.0, 800.0, 1150.0, 1500.0]
    assert maps[0]["impact_obliquity_deg"] == [0.0, 45.0]
    rows = list(csv.DictReader(io.StringIO(cells.read_text())))
    assert list(rows[0]) == ["plate", "impact_obliquity_deg", "impact_speed_m_s", "outcome",
                             "plate_failed", "exit_speed_m_s", "exit_obliquity_deg"]  # fmt: skip
    assert len(rows) == 2 * 2 * 5  # plates x obliquities x speeds
    for row in rows:  # the CSV's cells are the JSON's, cell by cell
        one = maps[0] if row["plate"] == "2024-T3/3.18" else maps[1]
        i = one["impact_obliquity_deg"].index(float(row["impact_obliquity_deg"]))
        j = one["impact_speed_m_s"].index(float(row["impact_speed_m_s"]))
        assert row["outcome"] == one["outcome"][i][j]
        assert float(row["exit_speed_m_s"]) == one["exit_speed_m_s"][i][j]
    # the physics at the corners: the slow normal impact stays in, the fast one goes through
    # with the exit speed below the impact speed; the slow 45 deg impact bounces off
    thin = maps[0]
    assert thin["outcome"][0][0] == "embedment" and thin["outcome"][0][-1] == "perforation"
    assert 0.0 < thin["exit_speed_m_s"][0][-1] < 1500.0
    assert thin["outcome"][1][0] == "ricochet" and thin["exit_obliquity_deg"][1][0] > 90.0


def test_map_without_an_output_is_one_line(tmp_path):
    code, _, err = run_cli(["map", *PLATE])
    assert_one_line(code, err, "--png FILE, --csv FILE or --json")
    code, _, err = run_cli(["map", "--kind", "limits", *PLATE, "--json"])
    assert_one_line(code, err, "--kind limits is a figure: give --png FILE")


def test_a_map_of_degrees_round_trips_its_rows():
    found = limits.outcome_map(
        pi.Simulation.from_names(), presets.DEFAULT_SPHERE, presets.plate("2024-T3/3.18"),
        (100.0, 900.0), 5, np.radians([0.0, 15.0]),
    )  # fmt: skip
    assert [line.to_json()["obliquity_deg"] for line in found.limits.lines] == [0.0, 15.0]
    assert math.isclose(found.limits.resolution, 200.0)


def test_limits_and_maps_go_into_an_archive_that_show_and_compare_read(tmp_path):
    archive = tmp_path / "limits.h5"
    coarse = ["--tolerance", "5"]  # what is checked is the archive's, not where limits lie
    code, out, err = run_cli([*ALONG_SPEED, *coarse, "--json", "--archive", str(archive)])
    assert code == 0, err
    printed = json.loads(out.splitlines()[0])
    assert out.splitlines()[1] == f"archive: {archive} (limits/2024-T3_3.18_plugging)"
    stored = limits.read_limits(archive, "2024-T3_3.18_plugging")
    assert [line.to_json() for line in stored.lines] == printed["lines"]
    code, _, err = run_cli([*ALONG_SPEED, *coarse, "--failure", "hinge", "--archive", str(archive)])
    assert code == 0, err
    small = ["--speeds", "100:900:9", "--obliquities", "0,45", "--png", str(tmp_path / "m.png")]
    stored_as = ["--archive", str(archive), "--name", "m"]
    code, out, err = run_cli(["map", *PLATE, *small, *coarse, *stored_as])
    assert code == 0, err
    assert isinstance(limits.read_limits(archive, "m"), limits.OutcomeMap)
    code, out, err = run_cli(["show", str(archive)])
    assert code == 0 and "limits/m: outcome map" in out, err
    code, out, err = run_cli(["compare", str(archive), "2024-T3_3.18_plugging",
                              "2024-T3_3.18_hinge"])  # fmt: skip
    assert code == 0 and "embedment after failure -> perforation" in out, err


def test_an_archive_that_cannot_take_the_result_is_refused_before_any_work(tmp_path):
    archive = tmp_path / "kept.h5"
    code, _, err = run_cli([*ALONG_SPEED, "--tolerance", "5", "--archive", str(archive)])
    assert code == 0, err
    archive.chmod(0o444)
    before = archive.read_bytes()
    code, out, err = run_cli([*ALONG_SPEED, "--archive", str(archive)])
    assert_one_line(code, err, "read-only")
    assert out == "" and archive.read_bytes() == before
    code, _, err = run_cli([*ALONG_SPEED, "--name", "x"])
    assert_one_line(code, err, "--name names what --archive stores")
