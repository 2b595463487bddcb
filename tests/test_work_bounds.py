"""Work is bounded before it starts and memory while it runs: scenes run 10,000 at a time
(the same results, bit for bit), lines are located a group at a time, and a request
over its bound is refused before any scene runs, naming the option that lifts it
(docs/robustness.md, "The input domain and the work bounds")."""

from __future__ import annotations

import numpy as np
import pytest
from test_output_files import assert_one_line, run_cli

import plateimpact as pi
from plateimpact import limits, presets
from plateimpact.errors import WorkBoundError
from plateimpact.limits import chunked, finder

SPHERE = presets.DEFAULT_SPHERE
PLATE = presets.plate("2024-T3/1.27")


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
