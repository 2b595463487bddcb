"""Calibration of a and b (eqs 40–49): shot data, the DRI fit, the report's Newton
iteration, the direct fit, the calibrate command and plate files.

Shots are made by the model from Table 1's constants at rtol 1e-10 and fitted at rtol 1e-8
(the default), so each test recovers constants it did not compute itself.
"""

from __future__ import annotations

import functools
import json
import math
from pathlib import Path

import numpy as np
import pytest

import plateimpact as pi
from plateimpact import presets
from plateimpact.cli import main
from plateimpact_plugins import report
from plateimpact_plugins.report import fits as _fits

SPHERE = presets.DEFAULT_SPHERE
FIT = pi.Simulation.from_names(integrator_settings={"rtol": 1e-8})
#: 12 impact speeds per plate [m/s], one or two below the model's ballistic limit.
SPEEDS = {
    "2024-T3/1.27": np.linspace(130.0, 700.0, 12),
    "2024-T3/3.18": np.linspace(330.0, 1500.0, 12),
    "2024-T3/6.35": np.linspace(520.0, 1500.0, 12),
    "6061-T6/9.53": np.linspace(620.0, 1500.0, 12),
    "SAE1010/1.47": np.linspace(280.0, 1500.0, 12),
}
ALUMINIUM = ["2024-T3/1.27", "2024-T3/3.18", "2024-T3/6.35", "6061-T6/9.53"]
EXAMPLE = Path(__file__).resolve().parents[1] / "studies" / "data" / "shots_2024T3_3.18mm.csv"
PLATE_FLAGS = ["--thickness", "3.18", "--pstar", "3", "--alpha", "45"]
HEADER = "impact_speed_m_s,impact_obliquity_deg,residual_speed_m_s"


@functools.cache
def shots_of(plate: str, noise: float = 0.0, seed: int | None = None, failure: str = "plugging"):
    simulation = pi.Simulation.from_names(failure=failure, integrator_settings={"rtol": 1e-10})
    return pi.synthetic_shots(
        presets.plate(plate), SPHERE, SPEEDS[plate], noise=noise, seed=seed, simulation=simulation
    )


def dri_shots(R: float, V0: float, speeds: np.ndarray) -> pi.Shots:
    residual = R * np.sqrt(np.clip(speeds**2 - V0**2, 0.0, None))
    return pi.Shots.from_columns(
        {
            "impact_speed_m_s": speeds,
            "impact_obliquity_deg": np.zeros(speeds.size),
            "residual_speed_m_s": np.minimum(residual, speeds),
        }
    )


def relative_error(fit: report.Calibration, plate: pi.Plate) -> tuple[float, float]:
    return abs(fit.a / plate.a - 1), abs(fit.b / plate.b - 1)


# ---------------------------------------------------------------------------- DRI fit


def test_dri_fit_of_exact_dri_data_recovers_R_and_V0_exactly():
    speeds = np.linspace(200.0, 1500.0, 10)  # three below V0 = 420: left out
    residual = 0.87 * np.sqrt(np.clip(speeds**2 - 420.0**2, 0.0, None))
    fit = pi.fit_dri(speeds, residual)
    assert fit.R == pytest.approx(0.87, rel=1e-12)
    assert fit.V0 == pytest.approx(420.0, rel=1e-12)
    assert fit.impact_speed.size == 8
    assert np.max(np.abs(fit.residuals)) < 1e-9 and fit.R_stderr < 1e-9
    assert fit.residual_speed(400.0) == 0.0


def test_dri_standard_errors_match_the_scatter_of_repeated_fits():
    # Noise on Vr² of constant size: eq 41 is then ordinary least squares, whose
    # standard errors must describe the spread of R and V0 over many data sets.
    rng = np.random.default_rng(11)
    speeds = np.linspace(500.0, 1500.0, 12)
    exact = 0.9**2 * (speeds**2 - 400.0**2)
    fits = [pi.fit_dri(speeds, np.sqrt(exact + 1e4 * rng.standard_normal(12))) for _ in range(400)]
    spread = np.std([[f.R, f.V0] for f in fits], axis=0)
    reported = np.mean([[f.R_stderr, f.V0_stderr] for f in fits], axis=0)
    assert reported == pytest.approx(spread, rel=0.15)


def test_dri_fit_without_a_ballistic_limit_is_a_calibration_error():
    speeds = np.linspace(300.0, 1500.0, 10)
    with pytest.raises(pi.CalibrationError, match="no ballistic limit"):
        pi.fit_dri(speeds, np.sqrt(0.8 * (speeds**2 + 200.0**2)))
    with pytest.raises(pi.CalibrationError, match="at least 3 perforating"):
        pi.fit_dri(speeds[:2], speeds[:2] / 2)


@pytest.mark.parametrize("plate_name", list(presets.PLATES))
def test_model_at_normal_incidence_is_the_dri_form_of_the_energy_balance(plate_name):
    # The model integrates eqs 25-30 with its own geometry and plugging; the closed form
    # a + b Vr² = (a + b Vs²) exp(-2bW/m) of docs/calibration.md must agree with it.
    plate = presets.plate(plate_name)
    R = math.exp(-plate.b * report.swept_volume(SPHERE, plate) / SPHERE.mass)
    V0 = math.sqrt(plate.a / plate.b * (1 / R**2 - 1))
    speeds = np.linspace(1.05 * V0, 1500.0, 8)
    result = pi.Simulation.from_names().run_batch(
        pi.SceneBatch.grid(SPHERE, plate, speeds, np.zeros(1))
    )
    assert np.all(result.outcome == pi.Outcome.PERFORATION)
    closed_form = R * np.sqrt(speeds**2 - V0**2)
    assert np.max(np.abs(result.exit_speed - closed_form) / speeds) < 1e-6
    assert report.energy_balance_start(R, V0, SPHERE, plate) == pytest.approx((plate.a, plate.b))


# ---------------------------------------------------------------- Newton and direct


@pytest.mark.parametrize("plate_name", list(presets.PLATES))
def test_both_methods_recover_table_1_from_noise_free_shots(plate_name):
    plate, shots = presets.plate(plate_name), shots_of(plate_name)
    newton = report.newton_fit(shots, plate, simulation=FIT)
    direct = report.direct_fit(shots, plate, simulation=FIT)
    assert max(relative_error(newton, plate)) < 1e-3
    assert max(relative_error(direct, plate)) < 1e-3
    # From the documented start (exact for plugging at normal incidence: tested above)
    # what is left is integrator error; studies/calibration_recovery.py counts the steps.
    assert newton.converged
    assert newton.dri_mismatch < _fits.NEWTON_TOLERANCE


@pytest.mark.parametrize("plate_name", list(presets.PLATES))
def test_newton_converges_from_the_thickness_reading_of_eqs_42_43(plate_name):
    # W = pi Rs² T (the length lost from eqs 42-43 read as the thickness) puts the start
    # 10-170 % off Table 1 for these plates: the iteration has real work to do.
    plate, shots = presets.plate(plate_name), shots_of(plate_name)
    dri = pi.fit_dri(shots.impact_speed, shots.residual_speed)
    start = report.energy_balance_start(
        dri.R, dri.V0, SPHERE, plate, volume=math.pi * SPHERE.radius**2 * plate.thickness
    )
    assert max(abs(start[0] / plate.a - 1), abs(start[1] / plate.b - 1)) > 0.05
    newton = report.newton_fit(shots, plate, simulation=FIT, start=start)
    assert newton.converged and newton.iterations >= 1
    assert max(relative_error(newton, plate)) < 1e-3


def test_newton_corrects_the_start_for_the_hinge_failure_model():
    # The start assumes plugging; with the hinge (finger) model the model's R and V0
    # differ from it and the iteration must move a and b back to Table 1.
    plate = presets.plate("SAE1010/1.47")
    hinge = pi.Simulation.from_names(failure="hinge", integrator_settings={"rtol": 1e-8})
    shots = shots_of("SAE1010/1.47", failure="hinge")
    newton = report.newton_fit(shots, plate, simulation=hinge)
    assert newton.converged and newton.iterations >= 1
    assert max(relative_error(newton, plate)) < 1e-3


@pytest.mark.parametrize("plate_name", ALUMINIUM)
def test_both_methods_recover_table_1_within_their_uncertainty_at_2_percent_noise(plate_name):
    plate, shots = presets.plate(plate_name), shots_of(plate_name, noise=0.02, seed=7)
    for fit in (
        report.newton_fit(shots, plate, simulation=FIT),
        report.direct_fit(shots, plate, simulation=FIT),
    ):
        assert abs(fit.a - plate.a) < 3 * fit.a_stderr, fit.method
        assert abs(fit.b - plate.b) < 3 * fit.b_stderr, fit.method
        # ... and the uncertainty says something: a few per cent to a few tens.
        assert fit.a_stderr < 0.25 * plate.a and fit.b_stderr < 0.25 * plate.b, fit.method
        assert fit.a_stderr > 1e-3 * plate.a and fit.b_stderr > 1e-3 * plate.b, fit.method


def test_shots_no_a_b_can_fit_are_reported_in_one_line():
    # Residual speeds rising faster than impact speed (R = 1.05): every b > 0 gives R < 1.
    shots = dri_shots(1.05, 300.0, np.linspace(320.0, 1500.0, 12))
    with pytest.raises(pi.ConvergenceError) as caught:
        report.newton_fit(shots, presets.plate("2024-T3/3.18"), simulation=FIT)
    message = str(caught.value)
    assert "\n" not in message and "R >= 1" in message and "Newton" in message
    assert isinstance(caught.value, pi.PlateImpactError)


def test_newton_stops_at_max_iterations_with_one_line():
    plate, shots = presets.plate("SAE1010/1.47"), shots_of("SAE1010/1.47")
    far = (3 * plate.a, 3 * plate.b)
    with pytest.raises(pi.ConvergenceError, match="no convergence in 1 iterations") as caught:
        report.newton_fit(shots, plate, simulation=FIT, start=far, max_iterations=1)
    assert "\n" not in str(caught.value)
    last = report.newton_fit(
        shots, plate, simulation=FIT, start=far, max_iterations=1, raise_on_failure=False
    )
    assert not last.converged and last.iterations == 1 and last.dri_mismatch > 1e-6


# ----------------------------------------------------------------------- shot data


def test_csv_columns_in_any_order_with_extra_columns_and_comments(tmp_path):
    base = "impact_speed_m_s,impact_obliquity_deg,residual_speed_m_s,outcome\n"
    rows = ["500,0,300,perforation", "300,0,0,embedment", "800,30,650,"]
    first = tmp_path / "a.csv"
    first.write_text(base + "\n".join(rows) + "\n")
    second = tmp_path / "b.csv"
    second.write_text(
        "# measured 2024\nnote,outcome,residual_speed_m_s,impact_obliquity_deg,impact_speed_m_s\n"
        "x,perforation,300,0,500\n\ny,embedment,0,0,300\nz,,650,30,800\n"
    )
    a, b = pi.Shots.from_csv(first), pi.Shots.from_csv(second)
    for column in ("impact_speed", "impact_obliquity", "residual_speed", "outcome"):
        np.testing.assert_array_equal(getattr(a, column), getattr(b, column))
    assert b.impact_obliquity[2] == pytest.approx(math.radians(30))
    assert list(b.outcome) == [pi.Outcome.PERFORATION, pi.Outcome.EMBEDMENT, 0]
    assert b.labels[1] == f"{second} line 5"
    assert len(a.normal_incidence()) == 2


def test_shots_from_python_columns_are_validated_like_csv():
    good = pi.Shots.from_columns(
        {
            "residual_speed_m_s": [0, 250.5],
            "impact_speed_m_s": [300, "500"],
            "impact_obliquity_deg": [0, 0],
        }  # fmt: skip
    )
    assert list(good.residual_speed) == [0.0, 250.5] and list(good.perforated) == [False, True]
    with pytest.raises(pi.ShotDataError, match=r"shots row 1, column residual_speed_m_s"):
        pi.Shots.from_columns(
            {
                "impact_speed_m_s": [300, 500],
                "impact_obliquity_deg": [0, 0],
                "residual_speed_m_s": [0, 600],
            }  # fmt: skip
        )


BAD_DATA = [
    pytest.param("", "empty file", id="empty-file"),
    pytest.param("# only a comment\n", "empty file", id="comment-only"),
    pytest.param(f"{HEADER}\n", "no shots", id="header-only"),
    pytest.param(
        "impact_speed_m_s,impact_obliquity_deg\n500,0\n",
        "missing column residual_speed_m_s",
        id="missing-column",
    ),
    pytest.param(
        f"{HEADER}\n500,0,300\n-400,0,0\n", "line 3, column impact_speed_m_s", id="negative-speed"
    ),
    pytest.param(f"{HEADER}\n500,0,300\nfast,0,0\n", "'fast'", id="non-numeric-speed"),
    pytest.param(f"{HEADER}\n500,0,-3\n", "line 2, column residual_speed_m_s", id="negative-vr"),
    pytest.param(f"{HEADER}\n500,0,600\n", "must not exceed the impact speed", id="vr-above-vs"),
    pytest.param(f"{HEADER}\n500,0,nan\n", "must be finite", id="nan"),
    pytest.param(f"{HEADER}\n500,95,0\n", "column impact_obliquity_deg", id="obliquity"),
    pytest.param(f"{HEADER}\n500,0\n", "line 2: expected 3 fields", id="short-row"),
    pytest.param(f"{HEADER},outcome\n500,0,300,embedment\n", "embedment contradicts", id="outcome"),
    pytest.param(f"{HEADER}\n-1,0,0\n500,0,x\n", "(and 1 more bad rows)", id="two-bad-rows"),
    pytest.param(
        f"{HEADER}\n300,0,0\n500,0,300\n700,0,500\n900,30,700\n",
        "2 perforating shots at normal incidence",
        id="two-perforations",
    ),
]


@pytest.mark.parametrize(("text", "named"), BAD_DATA)
def test_bad_shot_data_is_one_line_and_exit_2(text, named, tmp_path, capsys):
    path = tmp_path / "shots.csv"
    path.write_text(text)
    assert main(["calibrate", str(path), *PLATE_FLAGS]) == 2
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and err.startswith("plateimpact: error: ")
    assert named in err and "shots.csv" in err


def test_missing_shot_file_and_bad_plate_flags_are_one_line(tmp_path, capsys):
    assert main(["calibrate", str(tmp_path / "none.csv"), *PLATE_FLAGS]) == 2
    assert "cannot read" in capsys.readouterr().err
    assert main(["calibrate", str(EXAMPLE), "--thickness", "0", "--pstar", "3", "--alpha", "45"])
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and "--thickness" in err
    assert main(["calibrate", str(EXAMPLE), "--thickness", "3", "--pstar", "inf", "--alpha", "45"])
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and "never fails" in err


# -------------------------------------------------------------- command and plate files


def test_calibrate_json_on_the_shipped_example(capsys):
    assert EXAMPLE.read_text().startswith("# SYNTHETIC DATA")
    assert main(["calibrate", str(EXAMPLE), *PLATE_FLAGS, "--rtol", "1e-8", "--json"]) == 0
    out = json.loads(capsys.readouterr().out)
    for key in ("a_N_m2", "b_kg_m3", "R", "V0_m_s", "a_stderr_N_m2", "b_stderr_kg_m3"):
        assert isinstance(out[key], float), key
    assert out["method"] == "newton" and out["newton"]["converged"]
    assert out["normal_incidence_shots"] == 15 and out["perforating_shots"] == 13
    # The example is 2% noise on Table 1's 2024-T3/3.18: both fits find it again.
    table = presets.plate("2024-T3/3.18")
    for fit in (out["newton"], out["direct"]):
        assert abs(fit["a_N_m2"] - table.a) < 3 * fit["a_stderr_N_m2"]
        assert abs(fit["b_kg_m3"] - table.b) < 3 * fit["b_stderr_kg_m3"]


def test_calibrate_out_plate_file_runs_like_the_explicit_flags(tmp_path, capsys):
    shots_csv = tmp_path / "exact.csv"
    shots_csv.write_text(shots_of("2024-T3/3.18").to_csv_text())
    plate_json, figure = tmp_path / "plate.json", tmp_path / "fit.png"
    args = ["calibrate", str(shots_csv), *PLATE_FLAGS, "--rtol", "1e-8", "--material", "2024-T3"]
    assert main([*args, "--out", str(plate_json), "--png", str(figure)]) == 0
    text = capsys.readouterr().out
    assert "newton (eqs 44-49)" in text and "direct least squares" in text
    assert figure.read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"

    saved = json.loads(plate_json.read_text())
    assert saved["format"] == "plateimpact-plate-1" and saved["units"]["a_N_m2"]
    table = presets.plate("2024-T3/3.18")
    assert saved["a_N_m2"] == pytest.approx(table.a, rel=1e-3)
    assert saved["b_kg_m3"] == pytest.approx(table.b, rel=1e-3)
    plate = pi.load_plate_file(plate_json)
    assert plate.critical_penetration == pytest.approx(3e-3) and plate.material == "2024-T3"

    scene = ["--speed", "700", "--obliquity", "30", "--json"]
    explicit = ["--thickness", "3.18", "--pstar", "3", "--alpha", "45"]
    explicit += ["--a", repr(saved["a_N_m2"]), "--b", repr(saved["b_kg_m3"])]
    assert main(["run", "--plate-file", str(plate_json), *scene]) == 0
    assert main(["run", *explicit, *scene]) == 0
    from_file, from_flags = (json.loads(x) for x in capsys.readouterr().out.splitlines())
    assert from_file["outcome"] == from_flags["outcome"]
    assert from_file["exit_speed_m_s"] == pytest.approx(from_flags["exit_speed_m_s"], rel=1e-12)
    sweep = ["sweep", "--plate-file", str(plate_json), "--speeds", "700", "--obliquities", "30"]
    assert main(sweep) == 0
    row = capsys.readouterr().out.splitlines()[1].split(",")
    assert float(row[4]) == pytest.approx(from_file["exit_speed_m_s"], rel=1e-12)


@pytest.mark.parametrize(
    ("content", "extra", "named"),
    [
        (None, ["--preset", "2024-T3/3.18"], "cannot be combined with --preset"),
        (None, ["--a", "1e9"], "cannot be combined with --a"),
        ("{", [], "not valid JSON"),
        ('{"format": "other"}', [], "not a plateimpact plate file"),
        ('{"format": "plateimpact-plate-1", "material": "x"}', [], "missing key thickness_mm"),
        (
            '{"format": "plateimpact-plate-1", "material": "x", "thickness_mm": 3, "pstar": 3}',
            [],
            "unknown key 'pstar'",
        ),
    ],
)
def test_bad_plate_files_are_one_line_and_exit_2(content, extra, named, tmp_path, capsys):
    path = tmp_path / "plate.json"
    if content is None:
        pi.save_plate_file(path, presets.plate("2024-T3/3.18"))
    else:
        path.write_text(content)
    code = main(["run", "--plate-file", str(path), *extra, "--speed", "500", "--obliquity", "0"])
    err = capsys.readouterr().err
    assert code == 2 and err.count("\n") == 1 and named in err


def test_plate_file_with_an_invalid_value_names_the_key(tmp_path):
    path = tmp_path / "plate.json"
    pi.save_plate_file(path, presets.plate("2024-T3/3.18"))
    path.write_text(path.read_text().replace('"alpha_deg": 45.0', '"alpha_deg": 95.0'))
    with pytest.raises(pi.PlateFileError, match="alpha_deg: failure_angle must be in"):
        pi.load_plate_file(path)
    with pytest.raises(pi.PlateFileError, match="cannot read"):
        pi.load_plate_file(tmp_path / "none.json")
