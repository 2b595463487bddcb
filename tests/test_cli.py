"""The plateimpact command: outputs in user units, one-line errors with exit code 2."""

from __future__ import annotations

import csv
import io
import json
import subprocess
import sys

import attrs
import numpy as np
import pytest

import plateimpact as pi
from plateimpact import presets
from plateimpact.cli import SWEEP_COLUMNS, main

RUN = ["run", "--preset", "2024-T3/6.35", "--speed", "500", "--obliquity", "30"]


def test_presets_lists_table_1(capsys):
    assert main(["presets", "--json"]) == 0
    listed = json.loads(capsys.readouterr().out)
    assert set(listed["plates"]) == set(presets.PLATES)
    assert listed["plates"]["SAE1010/1.47"]["pstar_mm"] == pytest.approx(4.6)
    assert listed["sphere"]["mass_g"] == pytest.approx(1.0497, abs=1e-4)
    assert main(["presets"]) == 0 and "6061-T6/9.53" in capsys.readouterr().out


def test_run_json_has_the_documented_fields(capsys):
    assert main([*RUN, "--json"]) == 0
    out = json.loads(capsys.readouterr().out)
    assert out["outcome"] in {"ricochet", "embedment", "perforation"}
    for key in ("exit_speed_m_s", "exit_obliquity_deg", "contact_time_s", "max_penetration_mm"):
        assert isinstance(out[key], float)
    assert isinstance(out["plate_failed"], bool)
    assert out["model"]["integrator"] == "dopri5"


CASES = [
    # (command-line options, plate changes [SI], plug-in names and settings for Python)
    ([], {}, {}),
    (
        ["--pstar", "5.1", "--alpha", "40", "--set", "integrator.rtol=1e-9"],
        {"critical_penetration": 5.1e-3, "failure_angle": np.radians(40.0)},
        {"integrator_settings": {"rtol": 1e-9}},
    ),
    (
        ["--failure", "hinge", "--set", "failure.finger_area_scale=0.5"],
        {},
        {"failure": "hinge", "failure_settings": {"finger_area_scale": 0.5}},
    ),
    (
        ["--integrator", "segment", "--step", "2e-2", "--set", "model.rest_speed_fraction=0.02"],
        {},
        {
            "integrator": "segment",
            "integrator_settings": {"step": 2e-2},
            "rest_speed_fraction": 0.02,
        },
    ),
    (
        ["--a", "8e8", "--b", "1100", "--radius", "2.5"],
        {"a": 8e8, "b": 1100.0},
        {},
    ),
]


@pytest.mark.parametrize(("options", "plate_changes", "model"), CASES)
def test_cli_run_is_the_python_api(options, plate_changes, model, capsys):
    assert main([*RUN, "--json", *options]) == 0
    out = json.loads(capsys.readouterr().out)
    plate = presets.plate("2024-T3/6.35").with_constants(**plate_changes)
    sphere = presets.DEFAULT_SPHERE
    if "--radius" in options:  # a new radius keeps the default sphere's density
        sphere = pi.Sphere.of_density(2.5e-3, presets.SPHERE_DENSITY)
    simulation = pi.Simulation.from_names(**model)
    expected = simulation.run(pi.Scene(sphere, plate, 500.0, np.radians(30.0)))
    for key, value in expected.as_user_dict().items():
        assert out[key] == value, key  # the same numbers, to the last bit
    assert out["model"] == json.loads(json.dumps(simulation.describe()))


def test_cli_sweep_is_the_python_api(capsys):
    args = ["sweep", "--preset", "SAE1010/1.47", "--speeds", "200:1200:6", "--obliquities", "0,45"]
    assert main([*args, "--failure", "variable-pstar"]) == 0
    rows = list(csv.DictReader(io.StringIO(capsys.readouterr().out)))
    batch = pi.SceneBatch.grid(
        presets.DEFAULT_SPHERE,
        presets.plate("SAE1010/1.47"),
        np.linspace(200.0, 1200.0, 6),
        np.radians([0.0, 45.0]),
    )
    result = pi.Simulation.from_names(failure="variable-pstar").run_batch(batch)
    assert len(rows) == len(result)
    for i, row in enumerate(rows):
        assert row["outcome"] == pi.Outcome(int(result.outcome[i])).label
        assert float(row["exit_speed_m_s"]) == result.exit_speed[i]  # SI: the same bits
        degrees, mm = np.degrees(result.exit_obliquity[i]), result.max_penetration[i] * 1e3
        assert float(row["exit_obliquity_deg"]) == pytest.approx(degrees, rel=1e-15)
        assert float(row["max_penetration_mm"]) == pytest.approx(mm, rel=1e-15)


def test_run_writes_a_trajectory(tmp_path, capsys):
    target = tmp_path / "path.csv"
    assert main([*RUN, "--trajectory", str(target)]) == 0
    rows = list(csv.DictReader(target.open()))
    assert rows[0]["penetration_mm"] == "0.0" and float(rows[0]["obliquity_deg"]) == pytest.approx(
        30
    )
    assert len(rows) > 100


def test_sweep_writes_one_row_per_scene(tmp_path, capsys):
    args = [
        "sweep",
        "--preset",
        "SAE1010/1.47",
        "--speeds",
        "100:1000:4",
        "--obliquities",
        "0,60",
        "--integrator",
        "segment",
        "--step",
        "4e-2",
    ]
    assert main(args) == 0
    rows = list(csv.reader(io.StringIO(capsys.readouterr().out)))
    assert tuple(rows[0]) == SWEEP_COLUMNS and len(rows) == 1 + 8
    assert [r[2] for r in rows[1:]] == ["0.0"] * 4 + ["60.0"] * 4
    target = tmp_path / "sweep.csv"
    assert main([*args[:4], "100,400", *args[5:], "--csv", str(target)]) == 0
    assert len(target.read_text().splitlines()) == 1 + 4
    assert "wrote 4 scenes" in capsys.readouterr().out


@pytest.mark.parametrize(
    ("args", "named"),
    [
        (["--speed", "-5"], "--speed"),
        (["--speed", "nan"], "--speed"),
        (["--speed", "0"], "--speed"),
        (["--obliquity", "90"], "--obliquity"),
        (["--obliquity", "-1"], "--obliquity"),
        (["--preset", "nope"], "unknown preset"),
        (["--pstar", "0"], "--pstar"),
        (["--pstar", "-2"], "--pstar"),
        (["--alpha", "0"], "--alpha"),
        (["--alpha", "95"], "--alpha"),
        (["--thickness", "0"], "--thickness"),
        (["--radius", "-1"], "--radius"),
        (["--mass", "0"], "--mass"),
        (["--a", "0"], "--a"),
        (["--integrator", "rk99"], "unknown integrator"),
        (["--failure", "shatter"], "unknown failure"),
        (["--integrator", "segment", "--step", "1"], "--step"),
        (["--rtol", "1"], "--rtol"),
        (["--step", "1e-3"], "has no setting 'step'"),
    ],
)
def test_run_bad_input_is_one_line_and_exit_2(args, named, capsys):
    code = main([*RUN, *args])
    err = capsys.readouterr().err
    assert code == 2
    assert err.count("\n") == 1 and err.startswith("plateimpact: error: ") and named in err


@pytest.mark.parametrize(
    "args",
    [
        ["run", "--preset", "2024-T3/6.35", "--speed", "fast", "--obliquity", "0"],
        ["run", "--speed", "100"],
        ["sweep", "--preset", "2024-T3/6.35", "--speeds", "1:2", "--obliquities", "0"],
        ["sweep", "--preset", "2024-T3/6.35", "--speeds", "100", "--obliquities", "x"],
        ["frobnicate"],
    ],
)
def test_malformed_arguments_are_one_line_and_exit_2(args, capsys):
    with pytest.raises(SystemExit) as info:
        code = main(args)
        raise SystemExit(code)
    assert info.value.code == 2
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and err.startswith("plateimpact: error: ")


def test_a_presets_thickness_alone_is_refused_as_it_would_change_nothing(capsys):
    """T is in no force law: a, b, P*, alpha* carry it, fitted at the preset's T."""
    for changed in (["--thickness", "5"], ["--set", "plate.thickness=5"]):
        assert main([*RUN, *changed]) == 2
        err = capsys.readouterr().err
        assert err.count("\n") == 1 and err.startswith(f"plateimpact: error: {changed[0]}")
        assert "fitted at 6.35 mm: give --a, --b, --pstar, --alpha for 5 mm" in err
        assert "plateimpact calibrate" in err
    assert main([*RUN, "--thickness", "5", "--a", "1e9", "--failure", "intact"]) == 2
    assert "give --b for 5 mm" in capsys.readouterr().err  # only what the model reads
    constants = ["--a", "1e9", "--b", "1200", "--pstar", "4", "--alpha", "45"]
    assert main([*RUN, "--thickness", "6.35", "--json"]) == 0  # the preset's own: no change
    assert json.loads(capsys.readouterr().out)["inputs"]["plate"]["thickness_mm"] == 6.35
    assert main([*RUN, "--thickness", "5", *constants, "--json"]) == 0
    assert json.loads(capsys.readouterr().out)["inputs"]["plate"]["thickness_mm"] == 5
    thin = presets.plate("2024-T3/6.35")
    assert attrs.evolve(thin, thickness=5e-3).thickness == 5e-3  # the API keeps its Plate


def test_custom_plate_needs_every_plate_option(capsys):
    assert main(["run", "--speed", "100", "--obliquity", "0", "--a", "1e9"]) == 2
    assert "missing --thickness, --b, --pstar, --alpha" in capsys.readouterr().err


def test_csv_into_a_missing_directory_is_refused_before_any_write(tmp_path, capsys):
    code = main(
        [
            "sweep",
            "--preset",
            "2024-T3/6.35",
            "--speeds",
            "100",
            "--obliquities",
            "0",
            "--csv",
            str(tmp_path / "missing" / "out.csv"),
        ]
    )
    assert code == 2 and "does not exist" in capsys.readouterr().err
    assert not (tmp_path / "missing").exists()


def test_installed_command_exits_2_without_traceback():
    done = subprocess.run(
        [sys.executable, "-m", "plateimpact.cli", *RUN[:-1], "95"], capture_output=True, text=True
    )
    assert done.returncode == 2
    assert done.stderr == (
        "plateimpact: error: --obliquity: impact_obliquity must be in [0, 90) deg, got 95 deg\n"
    )


@pytest.mark.parametrize("failure", ["plugging", "hinge", "variable-pstar", "intact"])
def test_every_failure_model_is_selectable_by_name(failure, capsys):
    assert (
        main(
            [
                "run",
                "--preset",
                "SAE1010/1.47",
                "--speed",
                "500",
                "--obliquity",
                "45",
                "--failure",
                failure,
                "--json",
            ]
        )
        == 0
    )
    assert json.loads(capsys.readouterr().out)["model"]["failure"] == failure


def test_crater_writes_csv_and_png(tmp_path, capsys):
    table, picture = tmp_path / "crater.csv", tmp_path / "crater.png"
    assert (
        main(
            [
                "crater",
                "--preset",
                "6061-T6/9.53",
                "--speed",
                "263",
                "--obliquity",
                "60",
                "--csv",
                str(table),
                "--png",
                str(picture),
                "--dpi",
                "50",
            ]
        )
        == 0
    )
    assert "ricochet; crater" in capsys.readouterr().out
    rows = list(csv.reader(table.open()))
    assert rows[0] == ["lateral_mm", "depth_mm"] and rows[1] == ["0.0", "0.0"]
    assert picture.read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"
    assert not list(tmp_path.glob(".plateimpact-*"))  # no temporary file left behind


def test_pstar_table_from_the_command_line(tmp_path, capsys):
    good = tmp_path / "table.csv"
    good.write_text(
        "obliquity_deg,ricochet_pstar_mm,perforation_pstar_mm,"
        "transition_start_m_s,transition_end_m_s\n0,3.0,3.0,0,0\n"
    )
    base = [
        "run",
        "--preset",
        "SAE1010/1.47",
        "--speed",
        "500",
        "--obliquity",
        "45",
        "--json",
    ]
    assert main([*base, "--failure", "variable-pstar", "--pstar-table", str(good)]) == 0
    assert main([*base, "--failure", "variable-pstar", "--set", f"failure.table={good}"]) == 0
    assert main([*base, "--pstar", "3.0"]) == 0
    variable, generic, constant = (json.loads(x) for x in capsys.readouterr().out.splitlines())
    assert variable["exit_speed_m_s"] == generic["exit_speed_m_s"] == constant["exit_speed_m_s"]

    bad = tmp_path / "bad.csv"
    bad.write_text(
        "obliquity_deg,ricochet_pstar_mm,perforation_pstar_mm,"
        "transition_start_m_s,transition_end_m_s\n45,3,3,0,0\n30,3,3,0,0\n"
    )
    for args, expected in [
        (["--failure", "variable-pstar", "--pstar-table", str(bad)], "strictly increasing"),
        (
            ["--failure", "variable-pstar", "--pstar-table", str(tmp_path / "none.csv")],
            "cannot read",
        ),
        (["--pstar-table", str(good)], "has no setting 'table'"),
    ]:
        assert main([*base, *args]) == 2
        err = capsys.readouterr().err
        assert err.count("\n") == 1 and expected in err
