"""P* (and α*) fitted to oblique shots: the probability model against closed forms, the
recovery of a known P* and of a known variable-P* table, and bad input
(docs/calibration.md, "P* and α* from oblique shots")."""

from __future__ import annotations

import errno
import json
import math
import os

import numpy as np
import pytest
from scipy import integrate, stats

import plateimpact as pi
from plateimpact import limits, presets
from plateimpact.calibration import Cost
from plateimpact.calibration.outcome_model import (
    OUTCOME_BLUNDER,
    Bands,
    ProbabilityModel,
    ShotLines,
    _residual_moments,
    allowed_outcomes,
    log_likelihood,
)
from plateimpact.cli import main
from plateimpact.model.results import Outcome
from plateimpact.storage import output
from plateimpact_plugins.report import fits as report_fits
from plateimpact_plugins.report import pstar_fits as pstar
from plateimpact_plugins.report import pstar_search
from plateimpact_plugins.report.pstar_search import PstarEstimate
from plateimpact_plugins.variable_pstar import TABLE_COLUMNS, PstarTable

RIC, EMB, PERF = (1 << int(o) for o in Outcome)
SPEED_SIGMA, RESIDUAL_SIGMA = 10.0, 5.0  # [m/s], the noise the shots are made with
#: Coarse finder settings and a looser integrator keep the fits fast; the shots are made
#: with the same integrator, so the model the fit searches is the one that made them.
FAST = ["--rtol", "1e-6", "--resolution", "4", "--tolerance", "0.25"]


def one_line(shots_speed, allowed, residual=None, obliquity=0.0) -> ShotLines:
    n = len(shots_speed)
    return ShotLines(
        np.asarray(shots_speed, dtype=float), np.zeros(n, dtype=np.int64),
        np.asarray(allowed, dtype=np.int64),
        np.full(n, np.nan) if residual is None else np.asarray(residual, dtype=float),
        np.ones(n), np.array([obliquity]), np.array([3.175e-3]), np.array([1e-3]),
        np.array([0.0]), np.array([1000.0]),
    )  # fmt: skip


def test_the_outcome_probability_is_the_normal_mass_of_the_bands():
    # ricochet below 300, embedment 300-350, perforation above 350 m/s
    bands = Bands(np.array([-np.inf, 300.0, 350.0, np.inf]), np.array([1, 2, 3]),
                  np.zeros(0), np.zeros(0), 350.0)  # fmt: skip
    speeds = np.array([280.0, 310.0, 340.0, 360.0, 400.0])
    allowed = np.array([RIC, EMB, EMB | RIC, PERF, RIC])
    s = 7.0
    value, sigma = log_likelihood(one_line(speeds, allowed), [bands], ProbabilityModel(s))
    below, above = stats.norm.cdf((300.0 - speeds) / s), stats.norm.cdf((350.0 - speeds) / s)
    mass = {RIC: below, EMB: above - below, PERF: 1.0 - above}
    p = np.array([sum(mass[b][i] for b in mass if a & b) for i, a in enumerate(allowed)])
    choices = np.array([1, 1, 2, 1, 1])
    expected = np.sum(np.log((1 - OUTCOME_BLUNDER) * p + OUTCOME_BLUNDER * choices / 3))
    assert value == pytest.approx(expected, rel=1e-12)
    assert math.isnan(sigma)  # no residual speeds
    # a shot far on the wrong side costs the blunder floor, not minus infinity
    far, _ = log_likelihood(one_line([1000.0], [RIC]), [bands], ProbabilityModel(s))
    assert far == pytest.approx(math.log(OUTCOME_BLUNDER / 3), rel=1e-9)


def test_the_residual_speed_moments_are_those_over_the_perforating_speeds():
    """g(u) = c (u − V)^½ above V, interpolated exactly (g² is linear): mean and
    variance of g(u) for u ~ N(v, s²) given u > V, against quadrature."""
    limit, c, s = 400.0, 12.0, 10.0
    u = np.arange(limit, 700.0, 1.0)
    bands = Bands(np.array([-np.inf, limit, np.inf]), np.array([2, 3]), u,
                  c * np.sqrt(u - limit), limit)  # fmt: skip
    v = np.array([380.0, 405.0, 430.0, 480.0])
    shots = one_line(v, np.full(v.size, PERF), residual=np.full(v.size, 50.0))
    mean, variance = _residual_moments(shots, [bands], s, np.ones(v.size, bool))
    for vi, m, var in zip(v, mean, variance, strict=True):
        weight = stats.norm.sf(limit, vi, s)

        def integrand(x: float, k: int, vi: float = vi) -> float:
            return (c * np.sqrt(x - limit)) ** k * stats.norm.pdf(x, vi, s)

        moment = [
            integrate.quad(integrand, limit, vi + 15 * s + 100, args=(k,), points=[vi])[0] / weight
            for k in (1, 2)
        ]
        assert m == pytest.approx(moment[0], rel=5e-3)
        assert var == pytest.approx(moment[1] - moment[0] ** 2, rel=0.05)


def test_what_each_record_allows_for_each_question():
    outcome = np.array([1, 2, 3, 0, 0])
    perforated = np.array([False, False, True, True, False])
    assert allowed_outcomes(outcome, perforated, "outcome").tolist() == [
        RIC, EMB, PERF, PERF, RIC | EMB,
    ]  # fmt: skip
    assert allowed_outcomes(outcome, perforated, "perforation").tolist() == [
        RIC | EMB, RIC | EMB, PERF, PERF, RIC | EMB,
    ]  # fmt: skip
    # go/no-go "not perforated" cannot tell a ricochet from an embedment: not used
    assert allowed_outcomes(outcome, perforated, "ricochet").tolist() == [
        RIC, EMB | PERF, EMB | PERF, EMB | PERF, 0,
    ]  # fmt: skip


def berkson_shots(simulation, plate, speeds, obliquities, seed):
    """Shots whose true impact speed is the recorded one + N(0, s²) (the model's outcome
    and residual speed there, + N(0, σ_r²) on the residual speed): the probability model
    of the fit (docs/calibration.md)."""
    rng = np.random.default_rng(seed)
    speeds, obliquities = np.broadcast_arrays(np.asarray(speeds, float), obliquities)
    n = speeds.size
    true = speeds + SPEED_SIGMA * rng.standard_normal(n)
    labels = tuple(f"shot {i}" for i in range(n))
    blank = np.full(n, np.nan)
    truth = pi.Shots(true, obliquities, blank, blank, np.zeros(n, int), labels)
    result = simulation.run_batch(truth.scenes(presets.DEFAULT_SPHERE, plate))
    perforated = result.outcome == Outcome.PERFORATION
    noisy = result.exit_speed + RESIDUAL_SIGMA * rng.standard_normal(n)
    residual = np.where(perforated, np.maximum(noisy, 1.0), 0.0)
    return pi.Shots(speeds, obliquities, residual, blank, result.outcome.astype(int), labels)


@pytest.fixture(scope="module")
def aluminium_shots(tmp_path_factory):
    """2024-T3/3.18 (P* = 3.0 mm) at 30, 45, 60 deg, across each obliquity's boundaries."""
    simulation = pi.Simulation.from_names(integrator_settings={"rtol": 1e-6})
    speeds = np.concatenate(
        [np.linspace(360, 460, 8), np.linspace(430, 530, 8), np.linspace(600, 730, 8)]
    )
    obliquities = np.radians(np.repeat([30.0, 45.0, 60.0], 8))
    shots = berkson_shots(simulation, presets.plate("2024-T3/3.18"), speeds, obliquities, 3)
    path = tmp_path_factory.mktemp("pstar") / "shots.csv"
    path.write_text(shots.to_csv_text())
    return path


def test_pstar_is_recovered_from_oblique_shots_within_its_uncertainty(
    aluminium_shots, tmp_path, capsys
):
    plate_file = tmp_path / "fitted.json"
    args = ["calibrate", str(aluminium_shots), "--fit", "pstar", "--preset", "2024-T3/3.18",
            "--json", "--out", str(plate_file), *FAST]  # fmt: skip
    assert main(args) == 0
    found = json.loads(capsys.readouterr().out)
    error = found["pstar_mm"] - 3.0
    assert abs(error) < 3 * found["pstar_mm_stderr"]
    assert found["pstar_mm_stderr"] < 0.05 * 3.0
    assert found["converged"] and not found["alpha_fitted"] and found["alpha_deg"] == 45.0
    assert found["shots"] == 24 and found["residual_speed_shots"] > 0
    assert found["probability_model"]["speed_sigma_m_s"] == 10.0
    assert found["shots_near_boundary"] > 0 and found["log_likelihood"] < 0
    plate = pi.load_plate_file(plate_file)
    assert plate.critical_penetration == pytest.approx(found["pstar_mm"] * 1e-3, rel=1e-12)
    assert (plate.a, plate.b) == (presets.plate("2024-T3/3.18").a, presets.plate("2024-T3/3.18").b)


SAE_TABLE = [(0.0, 4.6, 4.6, 300.0, 330.0), (45.0, 3.5, 4.4, 344.0, 402.0),
             (60.0, 3.0, 3.8, 442.0, 536.0)]  # fmt: skip


def test_the_by_obliquity_fit_recovers_the_variable_pstar_table(tmp_path, capsys):
    plate = presets.plate("SAE1010/1.47")
    table = PstarTable.from_rows(SAE_TABLE)
    rtol = {"rtol": 1e-6}
    made_by = pi.Simulation.from_names(
        failure="variable-pstar", failure_settings={"table": table}, integrator_settings=rtol
    )
    constant = pi.Simulation.from_names(integrator_settings=rtol)
    # Why the table's values are what the fit must find: each band lies between the
    # last ricochet with the ricochet-range P* and the first perforation with the
    # perforation-range P*, so those two limits are the table model's own.
    sphere, obliquities = presets.DEFAULT_SPHERE, np.radians([45.0, 60.0])
    by_table = limits.along_speed(made_by, sphere, plate, obliquities, (300, 600), resolution=2)
    for line, (_, ricochet, perforation, _, _) in zip(by_table.lines, SAE_TABLE[1:], strict=True):
        for value, limit in ((ricochet, "ricochet_limit"), (perforation, "ballistic_limit")):
            with_constant = limits.along_speed(
                constant, sphere, plate.with_constants(critical_penetration=value * 1e-3),
                [line.fixed], (300, 600), resolution=2,
            ).lines[0]  # fmt: skip
            assert getattr(line, limit) == pytest.approx(getattr(with_constant, limit), abs=0.02)
    speeds = np.concatenate(
        [np.linspace(290, 370, 10), np.linspace(310, 450, 14), np.linspace(410, 580, 14)]
    )
    shots = berkson_shots(made_by, plate, speeds,
                          np.radians(np.repeat([0.0, 45.0, 60.0], [10, 14, 14])), 1)  # fmt: skip
    shots_csv, table_csv = tmp_path / "steel.csv", tmp_path / "table.csv"
    shots_csv.write_text(shots.to_csv_text())
    args = ["calibrate", str(shots_csv), "--fit", "pstar", "--by-obliquity", "--preset",
            "SAE1010/1.47", "--residual-sigma", "5", "--json", "--out", str(table_csv),
            *FAST]  # fmt: skip
    assert main(args) == 0
    found = json.loads(capsys.readouterr().out)
    fitted = PstarTable.from_csv(table_csv).rows()
    assert [row[0] for row in fitted] == pytest.approx([0.0, 45.0, 60.0], abs=1e-12)
    for row, truth, (_, ricochet, perforation, _, _) in zip(
        found["rows"], fitted, SAE_TABLE, strict=True
    ):
        assert truth[1:3] == pytest.approx((row["ricochet_pstar_mm"], row["perforation_pstar_mm"]),
                                           rel=1e-5)  # the file holds the fit  # fmt: skip
        if row["obliquity_deg"] == 0.0:  # no ricochet at normal incidence: not identified
            assert not row["ricochet_identified"] and row["ricochet_pstar_mm_stderr"] is None
            assert row["ricochet_pstar_mm"] == row["perforation_pstar_mm"]
            assert any("ricochet range" in note for note in row["notes"])
        else:
            error = abs(row["ricochet_pstar_mm"] - ricochet)
            assert error < 3 * row["ricochet_pstar_mm_stderr"] < 0.15 * ricochet
        error = abs(row["perforation_pstar_mm"] - perforation)
        assert error < 3 * row["perforation_pstar_mm_stderr"] < 0.15 * perforation
        assert row["transition_start_m_s"] <= row["transition_end_m_s"]
    header = table_csv.read_text().splitlines()[0].split(",")
    assert tuple(header[:5]) == TABLE_COLUMNS == pstar.TABLE_COLUMNS  # the plug-in's reader
    assert header[5:] == ["ricochet_pstar_stderr_mm", "perforation_pstar_stderr_mm"]
    run = ["run", "--preset", "SAE1010/1.47", "--speed", "500", "--obliquity", "50",
           "--failure", "variable-pstar", "--pstar-table", str(table_csv)]  # fmt: skip
    assert main(run) == 0


PLATE = ["--preset", "2024-T3/3.18"]


@pytest.mark.parametrize(
    ("extra", "message"),
    [
        (["--fit", "pstar", "--thickness", "3.18", "--alpha", "45"], "holds a and b fixed"),
        (["--fit", "pstar", "--thickness", "3.18", "--a", "1e9", "--alpha", "45"],
         "holds a and b fixed"),
        (["--speed-sigma", "5", *PLATE], "--speed-sigma: only with --fit pstar"),
        (["--by-obliquity", *PLATE], "--by-obliquity: only with --fit pstar"),
        (["--fit", "pstar", "--method", "direct", *PLATE], "--method: only with --fit ab"),
        (["--fit", "pstar", "--by-obliquity", "--alpha-fit", *PLATE], "--alpha-fit: not with"),
        (["--fit", "pstar", "--speed-sigma", "0", *PLATE], "--speed-sigma: speed_sigma must be"),
        (["--fit", "pstar", "--residual-sigma", "nan", *PLATE], "--residual-sigma:"),
        (["--fit", "pstar", "--tolerance", "0", *PLATE], "--tolerance: tolerance must be in"),
        (["--fit", "pstar", "--resolution", "0.001", *PLATE], "[0.01, 100] m/s"),
        # below one ulp of the shots' speeds: the old finder never returned
        (["--fit", "pstar", "--tolerance", "1e-14", *PLATE], "[1e-09, 10] m/s"),
        (["--fit", "pstar", "--by-obliquity", "--tolerance", "1e-300", *PLATE], "--tolerance: "),
        (["--fit", "pstar", "--failure", "variable-pstar", *PLATE], "does not read"),
        (["--fit", "pstar", "--pstar", "3", *PLATE], "--pstar: not with --fit pstar"),
        (["--fit", "pstar", "--set", "plate.pstar=3", *PLATE], "plate.pstar: not with --fit"),
        (["--fit", "pstar", "--alpha-fit", "--failure", "intact", *PLATE], "does not read"),
    ],
)  # fmt: skip
def test_bad_options_are_one_line_and_exit_code_2(aluminium_shots, capsys, extra, message):
    assert main(["calibrate", str(aluminium_shots), *extra]) == 2
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and message in err and "Traceback" not in err


def test_too_few_shots(tmp_path, capsys):
    path = tmp_path / "few.csv"
    rows = ("400,45,ricochet", "450,45,embedment", "500,45,perforation", "520,45,perforation")
    path.write_text("\n".join(["impact_speed_m_s,impact_obliquity_deg,outcome", *rows]) + "\n")
    assert main(["calibrate", str(path), "--fit", "pstar", *PLATE]) == 2
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and "4 shots with weight > 0, at least 5 needed" in err
    assert main(["calibrate", str(path), "--fit", "pstar", "--by-obliquity", *PLATE]) == 2
    assert "4 shots, at least 5 needed" in capsys.readouterr().err


def test_shots_far_from_every_boundary_do_not_identify_pstar(tmp_path, capsys):
    """Slow ricochets at 60 deg, and one embedment at 30 m/s that no P* explains: only a
    P* below about 0.7 mm makes the ricochets perforate, so the shots bound P* from below
    and say nothing more."""
    path = tmp_path / "far.csv"
    rows = "".join(f"{v},60,ricochet\n" for v in (100, 110, 120, 130, 140, 150))
    path.write_text("impact_speed_m_s,impact_obliquity_deg,outcome\n" + rows + "30,60,embedment\n")
    assert main(["calibrate", str(path), "--fit", "pstar", *PLATE, *FAST]) == 2
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and "P* not identified: the likelihood does not fall" in err
    assert "from one side only" in err
    # shots that no P* in the range moves: the likelihood is flat
    rows = "".join(f"{v},0,embedment\n" for v in (10, 11, 12, 13, 14)) + "12,0,ricochet\n"
    path.write_text("impact_speed_m_s,impact_obliquity_deg,outcome\n" + rows)
    assert main(["calibrate", str(path), "--fit", "pstar", *PLATE, *FAST]) == 2
    assert "P* not identified: the likelihood is flat" in capsys.readouterr().err


def test_a_search_that_does_not_converge_is_one_line(aluminium_shots, capsys, monkeypatch):
    monkeypatch.setattr(pstar_search, "MAX_ITERATIONS", 1)  # Chandrupatla needs more
    assert main(["calibrate", str(aluminium_shots), "--fit", "pstar", *PLATE, *FAST]) == 2
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and "P* fit did not converge" in err


def test_an_alpha_fit_that_does_not_converge_is_one_line(aluminium_shots, capsys, monkeypatch):
    monkeypatch.setattr(pstar_search, "ALPHA_FIT_EVALUATIONS", 2)  # Nelder-Mead needs more
    # how finely the boundaries are found does not decide that: the coarsest finder
    coarse = ["--rtol", "1e-6", "--resolution", "50", "--tolerance", "5"]
    args = ["calibrate", str(aluminium_shots), "--fit", "pstar", "--alpha-fit", *PLATE, *coarse]
    assert main(args) == 2
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and "alpha* fit (Nelder-Mead) did not converge" in err


@pytest.mark.parametrize("by_obliquity", [False, True], ids=["plate file", "pstar table"])
def test_a_full_disk_at_out_keeps_the_old_file(
    aluminium_shots, tmp_path, capsys, monkeypatch, by_obliquity
):
    """--out goes through the atomic writer (the fit itself is canned: it is not what
    this test is about)."""
    estimate = PstarEstimate(3e-3, 3e-5, math.radians(45.0), log_likelihood=-10.0)
    model, cost = ProbabilityModel(), Cost()
    plate = presets.plate("2024-T3/3.18")
    fit = pstar.PstarFit(plate, estimate, False, model, 24, 0, "", cost)
    row = pstar.PstarRow(math.radians(45.0), estimate, estimate, 10, 10, 400.0, 450.0, ())
    table = pstar.PstarTableFit((row,), math.radians(45.0), model, cost)
    monkeypatch.setattr(report_fits, "fit_pstar", lambda *args, **kwargs: fit)
    monkeypatch.setattr(report_fits, "fit_pstar_by_obliquity", lambda *a, **k: table)
    target = tmp_path / ("table.csv" if by_obliquity else "plate.json")
    target.write_text("what was there\n")

    def full_disk(stage: str) -> None:
        if stage == "write":
            raise OSError(errno.ENOSPC, os.strerror(errno.ENOSPC))

    monkeypatch.setattr(output, "fault_point", full_disk)
    args = ["calibrate", str(aluminium_shots), "--fit", "pstar", *PLATE, "--out", str(target)]
    assert main(args + ["--by-obliquity"] * by_obliquity) == 2
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and "--out" in err and "No space left on device" in err
    assert target.read_text() == "what was there\n"
    assert sorted(p.name for p in tmp_path.iterdir()) == [target.name]
