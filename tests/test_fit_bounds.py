"""The P* fits are checked whole and bounded before any scene runs, and run in bounded
memory with progress (docs/calibration.md, "P* and α* from oblique shots";
docs/robustness.md, "The input domain and the work bounds").

"Before any scene runs" is held by a hook, not a clock: Simulation.run_batch raises
if it is called when the test says it must not be."""

from __future__ import annotations

import math

import numpy as np
import pytest
from test_output_files import assert_one_line, run_cli

import plateimpact as pi
from plateimpact import presets
from plateimpact.base.errors import WorkBoundError
from plateimpact.calibration import ProbabilityModel, ShotLines
from plateimpact.limits import chunked
from plateimpact.model.results import Outcome
from plateimpact_plugins import report
from plateimpact_plugins.report import pstar_plan, pstar_search

PLATE = presets.plate("2024-T3/3.18")
FAST = {"resolution": 4.0, "tolerance": 0.25}
RIC, EMB, PERF = (1 << int(o) for o in Outcome)


class SceneRan(AssertionError):
    pass


@pytest.fixture
def no_scene(monkeypatch: pytest.MonkeyPatch) -> None:
    """Any scene run during the test fails it at once."""

    def refuse(self, scenes, **kwargs):  # type: ignore[no-untyped-def]
        raise SceneRan("a scene ran before the request was refused")

    monkeypatch.setattr(pi.Simulation, "run_batch", refuse)


def csv_of(rows: list[tuple[float, float, str]], tmp_path) -> str:
    path = tmp_path / "shots.csv"
    path.write_text(
        "impact_speed_m_s,impact_obliquity_deg,outcome\n"
        + "".join(f"{v},{o},{outcome}\n" for v, o, outcome in rows)
    )
    return str(path)


def many_obliquities(count: int) -> list[tuple[float, float, str]]:
    """Three perforations at each of ``count`` obliquities: neither range of any of them
    can fix P* (the ricochet range holds 3 shots that all allow embedment or perforation,
    the perforation range 3 that all perforated)."""
    return [(v, o, "perforation") for o in range(count) for v in (900.0, 950.0, 1000.0)]


def test_every_obliquity_that_cannot_be_fitted_is_refused_at_once_before_any_scene(
    tmp_path, no_scene
):
    path = csv_of(many_obliquities(20), tmp_path)
    code, _, err = run_cli(["calibrate", path, "--fit", "pstar", "--by-obliquity",
                            "--preset", "2024-T3/3.18"])  # fmt: skip
    assert_one_line(
        code, err, "P* not identified at 0 deg: ricochet range: every one of its 3 shots "
        "allows embedment or perforation", "perforation range: every one of its 3 shots "
        "allows perforation", "(and 19 more obliquities: 1, 2, 3, 4, 5, 6, 7, 8, 9, 10, ... deg)",
    )  # fmt: skip


def test_one_fittable_range_at_each_obliquity_is_enough_to_go_on(tmp_path, no_scene):
    """Mixed outcomes in the perforation range at every obliquity: nothing is refused
    up front, so the fit reaches its first scene."""
    rows = [(v, o, outcome) for o in (30, 60) for v, outcome in
            ((500, "embedment"), (600, "perforation"), (700, "perforation"))]  # fmt: skip
    with pytest.raises(SceneRan):
        report.fit_pstar_by_obliquity(pi.Shots.from_csv(csv_of(rows, tmp_path)), PLATE, **FAST)


def test_a_set_that_plainly_cannot_fix_pstar_is_told_from_its_shots():
    def lines(allowed: list[int], residual: float = math.nan) -> ShotLines:
        n = len(allowed)
        return ShotLines(
            np.full(n, 500.0), np.zeros(n, np.int64), np.array(allowed),
            np.full(n, residual), np.ones(n), np.zeros(1), np.full(1, 3e-3), np.full(1, 1e-3),
            np.full(1, 400.0), np.full(1, 600.0),
        )  # fmt: skip

    assert "at least 5" in str(pstar_plan.unfittable(lines([RIC] * 4), 4, 5))
    assert "allows ricochet," in str(pstar_plan.unfittable(lines([RIC] * 5), 5, 5))
    # go/no-go "not perforated" and recorded ricochets have ricochet in common
    assert "allows ricochet" in str(pstar_plan.unfittable(lines([RIC | EMB, RIC] * 3), 6, 5))
    assert pstar_plan.unfittable(lines([RIC | EMB, PERF] * 3), 6, 5) is None
    # residual speeds can fix P* where the outcomes all agree
    assert pstar_plan.unfittable(lines([PERF] * 5, residual=100.0), 5, 5) is None


def aluminium_rows() -> list[tuple[float, float, str]]:
    """Embedments below and perforations above the 3.18-mm plate's ballistic limits,
    at three obliquities, speeds chosen so each line's scan can be counted by hand."""
    return [
        (v, o, "embedment" if v < limit else "perforation")
        for o, limit, speeds in ((30, 405, (370, 390, 420, 450)),
                                 (45, 470, (440, 460, 490, 520)),
                                 (60, 650, (610, 640, 670, 700)))
        for v in speeds
    ]  # fmt: skip


def test_the_estimate_is_the_scan_of_every_line_times_the_candidates():
    """Each line reaches 8 s = 80 m/s beyond its shots: 290-530, 360-600 and 530-780
    m/s, at 4 m/s that is 60, 60 and 63 intervals: 61 + 61 + 64 = 186 samples a
    candidate; 17 scan points and 10 search candidates (+ 118 with alpha*)."""
    shots = pi.Shots.from_columns(
        {"impact_speed_m_s": [r[0] for r in aluminium_rows()],
         "impact_obliquity_deg": [r[1] for r in aluminium_rows()],
         "outcome": [r[2] for r in aluminium_rows()]}
    )  # fmt: skip
    from plateimpact_plugins.report.pstar_fits import prepare

    prepared = prepare(shots, presets.DEFAULT_SPHERE, "outcome", ProbabilityModel())
    assert prepared.lines is not None
    assert pstar_plan.estimate_scenes([prepared.lines], 4.0, False) == 186 * 27
    assert pstar_plan.estimate_scenes([prepared.lines], 4.0, True) == 186 * (27 + 118)


@pytest.mark.parametrize("by_obliquity", [False, True])
def test_a_fit_over_its_bound_is_refused_before_any_scene(tmp_path, no_scene, by_obliquity):
    shots = pi.Shots.from_csv(csv_of(aluminium_rows(), tmp_path))
    fit = report.fit_pstar_by_obliquity if by_obliquity else report.fit_pstar
    with pytest.raises(WorkBoundError) as info:
        fit(shots, PLATE, max_scenes=1000, **FAST)
    assert "more than 1,000" in str(info.value) and "--force" in str(info.value)
    if not by_obliquity:  # alpha* multiplies the candidates by (27 + 118) / 27
        with pytest.raises(WorkBoundError, match="about 26,970 scenes"):
            report.fit_pstar(shots, PLATE, max_scenes=186 * 27, fit_alpha=True, **FAST)
        with pytest.raises(SceneRan):  # within the bound without alpha*: it starts
            report.fit_pstar(shots, PLATE, max_scenes=186 * 27, **FAST)


#: Shots on one line (45 deg, 430-530 m/s), and a coarse finder: a fit of a few seconds.
ONE_LINE = [(v, 45, "embedment" if v < 470 else "perforation") for v in range(430, 531, 20)]
COARSE = {"resolution": 8.0, "tolerance": 1.0}


def test_the_command_line_names_force_and_force_lifts_the_bound(tmp_path, monkeypatch):
    """One line, 350-610 m/s at 8 m/s: 33 intervals, 34 samples, x 27 candidates."""
    path = csv_of(ONE_LINE, tmp_path)
    monkeypatch.setattr("plateimpact_plugins.report.calibrate_pstar_command.MAX_FIT_SCENES", 900)
    argv = ["calibrate", path, "--fit", "pstar", "--preset", "2024-T3/3.18", "--rtol", "1e-6",
            "--resolution", "8", "--tolerance", "1"]  # fmt: skip
    code, _, err = run_cli(argv)
    assert_one_line(code, err, "P* fit: about 918 scenes", "more than 900", "--force")
    code, out, err = run_cli([*argv, "--force"])
    assert code == 0 and "P* = " in out, err


def test_a_fit_runs_a_chunk_at_a_time_and_keeps_no_samples_per_candidate(tmp_path, monkeypatch):
    """Chunks of 100 scenes: no batch larger, the progress bar told after every chunk,
    the same P* to the last bit; the memo of every candidate holds band edges only."""
    shots = pi.Shots.from_columns(  # 34 samples a candidate; residual speeds, so that
        {  # the likelihood reads the bands' samples
            "impact_speed_m_s": [v for v, _, _ in ONE_LINE],
            "impact_obliquity_deg": [o for _, o, _ in ONE_LINE],
            "outcome": [outcome for _, _, outcome in ONE_LINE],
            "residual_speed_m_s": [0.0 if v < 470 else (v - 460) * 2.0 for v, _, _ in ONE_LINE],
        }
    )
    simulation = pi.Simulation.from_names(integrator_settings={"rtol": 1e-6})
    model = ProbabilityModel(10.0, residual_sigma=5.0)
    told: list[int] = []
    monkeypatch.setattr("plateimpact.run.simulation.report_scenes", told.append)
    whole = report.fit_pstar(shots, PLATE, simulation=simulation, model=model, **COARSE)
    assert whole.residual_shots == 4
    assert max(told) == 17 * 34  # the scan of 17 candidates, one batch
    told.clear()
    monkeypatch.setattr(chunked, "RUN_CHUNK", 100)
    memos: list[pstar_search.Search] = []
    original = pstar_search.Search.__init__

    def remember(self, *args, **kwargs):  # type: ignore[no-untyped-def]
        original(self, *args, **kwargs)
        memos.append(self)

    monkeypatch.setattr(pstar_search.Search, "__init__", remember)
    samples: list[int] = []  # what the likelihood was given
    likelihood = pstar_search.log_likelihood

    def counting(shots, bands, model):  # type: ignore[no-untyped-def]
        samples.append(max(b.speeds.size for b in bands))
        return likelihood(shots, bands, model)

    monkeypatch.setattr(pstar_search, "log_likelihood", counting)
    parts = report.fit_pstar(shots, PLATE, simulation=simulation, model=model, **COARSE)
    assert max(told) == 100 and told[:6] == [100] * 5 + [78]  # the scan, chunked
    assert (parts.pstar, parts.pstar_stderr) == (whole.pstar, whole.pstar_stderr)
    (search,) = memos  # the samples served the likelihood and were dropped
    assert max(samples) > 0
    assert all(b.speeds.size == 0 for _, _, bands in search._memo.values() for b in bands)


def test_more_obliquities_than_a_table_takes_are_refused_before_grouping(
    tmp_path, no_scene, monkeypatch
):
    """1,001 obliquities (measured ones, each shot its own): refused from one sort of the
    obliquities, before the shots are grouped (a millisecond a group) or any scene runs."""
    rows = [(v, k * 0.08, "perforation") for k in range(1001) for v in (900.0, 950.0)]
    shots = pi.Shots.from_csv(csv_of(rows, tmp_path))

    def no_grouping(self):  # type: ignore[no-untyped-def]
        raise AssertionError("the shots were grouped")

    monkeypatch.setattr(pi.Shots, "groups_by_obliquity", no_grouping)
    with pytest.raises(
        pi.CalibrationError, match="shots at 1,001 obliquities, more than the 1,000"
    ):
        report.fit_pstar_by_obliquity(shots, PLATE, **FAST)
