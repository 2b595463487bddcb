"""Work is bounded before it starts and memory while it runs: scenes run 10,000 at a time
(the same results, bit for bit), lines are located a group at a time, and a request
over its bound is refused before any scene runs, naming the option that lifts it
(docs/robustness.md, "The input domain and the work bounds")."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest
from test_output_files import assert_one_line, run_cli

import plateimpact as pi
from plateimpact import limits, presets
from plateimpact.base.errors import WorkBoundError
from plateimpact.limits import bracketing as finder
from plateimpact.limits import chunked
from plateimpact_plugins import report
from plateimpact_plugins.report import fits as _fits

SPHERE = presets.DEFAULT_SPHERE
PLATE = presets.plate("2024-T3/1.27")
ROOT = Path(__file__).resolve().parents[1]


@pytest.fixture
def batches(monkeypatch: pytest.MonkeyPatch) -> list[int]:
    """The size of every batch Simulation.run_batch is given during the test."""
    sizes: list[int] = []
    original = pi.Simulation.run_batch

    def counting(self, scenes, **kwargs):  # type: ignore[no-untyped-def]
        result = original(self, scenes, **kwargs)
        sizes.append(len(result))
        return result

    monkeypatch.setattr(pi.Simulation, "run_batch", counting)
    return sizes


def find(simulation: pi.Simulation, **kwargs: object) -> limits.Limits:
    return limits.along_speed(
        simulation, SPHERE, PLATE, np.radians([30.0, 45.0, 60.0]), (100.0, 400.0),
        resolution=5.0, tolerance=0.1, **kwargs,  # type: ignore[arg-type]
    )  # fmt: skip


def test_scenes_run_a_chunk_at_a_time_and_lines_a_group_at_a_time_bit_for_bit(monkeypatch, batches):
    """Chunks of 50 scenes and groups of 70 samples (one line each) against one batch:
    the same boundaries to the last bit, and no batch larger than a chunk."""
    simulation = pi.Simulation.from_names()
    whole = find(simulation)
    assert max(batches) == 183  # the scan, 3 lines x 61 samples, in one batch
    batches.clear()
    monkeypatch.setattr(chunked, "RUN_CHUNK", 50)
    monkeypatch.setattr(finder, "GROUP_SCENES", 70)
    parts = find(simulation)
    assert max(batches) <= 50 and len(batches) > 5
    assert parts.scenes == whole.scenes
    for a, b in zip(parts.lines, whole.lines, strict=True):
        assert a.boundaries == b.boundaries and a.first == b.first


def test_a_scan_over_its_bound_is_refused_before_any_scene_and_max_scenes_none_lifts_it(
    batches,
):
    simulation = pi.Simulation.from_names()
    with pytest.raises(WorkBoundError) as info:
        find(simulation, max_scenes=182)  # 3 lines x 61 samples = 183 scenes
    assert info.value.parameter == "resolution" and "183 scenes, more than 182" in str(info.value)
    assert batches == []
    assert find(simulation, max_scenes=183).scenes >= 183
    assert find(simulation, max_scenes=None).scenes >= 183


def test_a_line_of_more_samples_than_a_group_holds_is_refused_even_unbounded(batches):
    with pytest.raises(pi.ParameterError, match="samples a line, more than 1,000,000"):
        limits.along_speed(
            pi.Simulation.from_names(), SPHERE, PLATE, [0.5], (100.0, 2000.0),
            resolution=1e-3, tolerance=1e-3, max_scenes=None,
        )  # fmt: skip
    assert batches == []


def test_the_command_line_names_force_and_force_lifts_the_bound(monkeypatch, batches):
    code, _, err = run_cli(["limits", "--preset", "2024-T3/1.27", "--obliquities", "0:89:100000"])
    assert_one_line(code, err, "--resolution: ", "195,100,000 scenes, more than 1,000,000",
                    "--force")  # fmt: skip
    assert batches == []
    monkeypatch.setattr(limits, "MAX_SCAN_SCENES", 100)  # 2 lines x 61 samples
    argv = ["limits", "--preset", "2024-T3/1.27", "--obliquities", "30,60", "--speeds",
            "100:400", "--resolution", "5", "--tolerance", "0.5"]  # fmt: skip
    code, _, err = run_cli(argv)
    assert_one_line(code, err, "122 scenes, more than 100", "--force")
    assert batches == []
    code, out, err = run_cli([*argv, "--force"])
    assert code == 0 and err == "" and "ballistic limit" in out


# -- validate and the a, b fit -------------------------------------------------------------

SHOTS = pi.Shots.from_columns(
    {"impact_speed_m_s": [400, 450, 600, 410, 500, 590],
     "impact_obliquity_deg": [30] * 3 + [60] * 3, "perforated": [0, 1, 1, 0, 0, 1]}
)  # fmt: skip


@pytest.fixture
def no_scene(monkeypatch: pytest.MonkeyPatch) -> None:
    def refuse(self, scenes, **kwargs):  # type: ignore[no-untyped-def]
        raise AssertionError("a scene ran before the request was refused")

    monkeypatch.setattr(pi.Simulation, "run_batch", refuse)


def test_validate_is_bounded_before_any_scene_by_its_shots_and_every_line(no_scene):
    """6 shots on 2 lines; boundaries sought over 200-900 m/s (half the slowest shot to
    1.5 times the fastest): 701 samples a line at 1 m/s, so 6 + 2 x 701 = 1,408 scenes."""
    simulation = pi.Simulation.from_names()
    with pytest.raises(WorkBoundError, match=r"up to 1,408 scenes .* more than 1,407: .*--force"):
        pi.validate(simulation, SPHERE, PLATE, SHOTS, max_scenes=1407)
    with pytest.raises(pi.ParameterError) as info:  # below what doubles resolve at 900 m/s
        pi.validate(simulation, SPHERE, PLATE, SHOTS, tolerance=1e-14)
    assert info.value.parameter == "tolerance"


def test_validate_runs_its_shots_a_chunk_at_a_time_bit_for_bit(monkeypatch, batches):
    simulation = pi.Simulation.from_names()
    coarse = {"resolution": 50.0, "tolerance": 5.0}  # a short boundary search
    whole = pi.validate(simulation, SPHERE, PLATE, SHOTS, **coarse)
    monkeypatch.setattr(chunked, "RUN_CHUNK", 4)
    batches.clear()
    parts = pi.validate(simulation, SPHERE, PLATE, SHOTS, **coarse)
    assert max(batches) <= 4
    for name in ("predicted_outcome", "predicted_exit_speed", "predicted_exit_obliquity"):
        np.testing.assert_array_equal(getattr(parts, name), getattr(whole, name))
    assert parts.disagreements == whole.disagreements


def test_validate_on_the_command_line_names_force_and_force_lifts_the_bound(tmp_path, monkeypatch):
    path = tmp_path / "shots.csv"
    path.write_text(SHOTS.to_csv_text())
    monkeypatch.setattr("plateimpact.cli.commands.validate.MAX_VALIDATE_SCENES", 1000)
    argv = ["validate", str(path), "--preset", "2024-T3/1.27"]
    code, _, err = run_cli(argv)
    assert_one_line(code, err, "validate: up to 1,408 scenes", "more than 1,000", "--force")
    code, out, err = run_cli([*argv, "--force"])
    assert code == 0 and "outcome agreement" in out, err


NORMAL = "studies/data/shots_2024T3_3.18mm.csv"  # 15 shots at normal incidence


def test_the_ab_fit_is_bounded_before_any_scene_by_its_normal_shots(no_scene, monkeypatch):
    """213 scenes a shot at most: 3 x (1 + 20) Newton runs, 3 x 50 direct-fit runs."""
    shots = pi.Shots.from_csv(ROOT / NORMAL)
    plate = presets.plate("2024-T3/3.18")
    with pytest.raises(WorkBoundError, match=r"up to 3,195 scenes .* more than 3,194"):
        report.calibrate(shots, plate, max_scenes=3194)
    monkeypatch.setattr("plateimpact_plugins.report.calibrate_command.MAX_FIT_SCENES", 3194)
    argv = ["calibrate", str(ROOT / NORMAL), "--thickness", "3.18", "--pstar", "3", "--alpha", "45"]
    code, _, err = run_cli(argv)
    assert_one_line(code, err, "a, b fit: up to 3,195 scenes", "--force")


def test_the_model_residual_speeds_run_a_chunk_at_a_time_bit_for_bit(monkeypatch, batches):
    simulation = pi.Simulation.from_names()
    plate = presets.plate("2024-T3/3.18")
    speeds, constants = np.linspace(300.0, 900.0, 7), [(1e9, 1200.0), (1.1e9, 1300.0)]
    whole = _fits.model_residual_speeds(simulation, SPHERE, plate, speeds, constants)
    assert batches == [14]
    monkeypatch.setattr(chunked, "RUN_CHUNK", 3)
    parts = _fits.model_residual_speeds(simulation, SPHERE, plate, speeds, constants)
    assert max(batches[1:]) <= 3
    np.testing.assert_array_equal(parts, whole)
    assert (whole > 0).any() and (whole == 0).any()


def test_validate_lists_ten_obliquities_and_counts_the_rest(tmp_path):
    path = tmp_path / "shots.csv"
    path.write_text(
        "impact_speed_m_s,impact_obliquity_deg,perforated\n"
        + "".join(f"{500 + k},{30 + k / 10},1\n" for k in range(12))
    )
    code, out, err = run_cli(["validate", str(path), "--preset", "2024-T3/1.27"])
    assert code == 0, err
    assert (
        "at 30, 30.1, 30.2, 30.3, 30.4, 30.5, 30.6, 30.7, 30.8, 30.9, ... (12 obliquities) deg"
        in out
    )
