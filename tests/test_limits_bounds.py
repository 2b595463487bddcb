"""Every limits request ends: a tolerance finer than a double resolves is refused before
any scene runs (the API names the parameter, the command line the flag and the range),
and the finder's refinement has a deterministic bound of its own (docs/limits.md,
docs/robustness.md "The input domain and the work bounds")."""

from __future__ import annotations

import math

import numpy as np
import pytest
from test_output_files import assert_one_line, run_cli

import plateimpact as pi
from plateimpact import limits, presets
from plateimpact.limits import bracketing as finder

SPHERE = presets.DEFAULT_SPHERE
PLATE = presets.plate("2024-T3/1.27")


@pytest.fixture
def scenes_run(monkeypatch: pytest.MonkeyPatch) -> list[int]:
    """How many scenes every Simulation.run_batch has run since the test began."""
    count = [0]
    original = pi.Simulation.run_batch

    def counting(self, scenes, **kwargs):  # type: ignore[no-untyped-def]
        result = original(self, scenes, **kwargs)
        count[0] += len(result)
        return result

    monkeypatch.setattr(pi.Simulation, "run_batch", counting)
    return count


@pytest.mark.parametrize(
    ("call", "parameter"),
    [
        # 1e-14 m/s is under one ulp of 184 m/s (2.8e-14): the bisection could never end
        (lambda s: limits.along_speed(s, SPHERE, PLATE, [0.8], tolerance=1e-14), "tolerance"),
        (lambda s: limits.along_speed(s, SPHERE, PLATE, [0.8], tolerance=1e-300), "tolerance"),
        (lambda s: limits.along_speed(s, SPHERE, PLATE, [0.8], tolerance=math.inf), "tolerance"),
        (lambda s: limits.along_speed(s, SPHERE, PLATE, [0.8], resolution=math.nan), "resolution"),
        (lambda s: limits.along_speed(s, SPHERE, PLATE, [0.8], resolution=math.inf), "resolution"),
        (lambda s: limits.along_speed(s, SPHERE, PLATE, [0.8], resolution=0.001), "resolution"),
        (lambda s: limits.along_obliquity(s, SPHERE, PLATE, [300.0], tolerance=1e-16), "tolerance"),
        (lambda s: limits.outcome_map(s, SPHERE, PLATE, tolerance=1e-14), "tolerance"),
        (lambda s: limits.outcome_map(s, SPHERE, PLATE, tolerance=math.nan), "tolerance"),
    ],
)  # fmt: skip
def test_a_tolerance_finer_than_doubles_resolve_is_refused_before_any_scene(
    call, parameter, scenes_run
):
    with pytest.raises(pi.ParameterError) as info:
        call(pi.Simulation.from_names())
    assert info.value.parameter == parameter and "\n" not in str(info.value)
    assert scenes_run == [0]


def test_the_floor_is_relative_to_the_largest_value_of_the_range():
    """1e-13 of the range's largest value: 2e-10 m/s over 50-2000 m/s, and 1e-13 rad
    (5.7e-12 deg) over 0-1 rad."""
    assert finder.finest_tolerance(np.array([50.0]), np.array([2000.0])) == pytest.approx(2e-10)
    assert finder.finest_tolerance(np.array([0.0]), np.array([1.0])) == pytest.approx(1e-13)


@pytest.mark.parametrize(
    ("argv", "named"),
    [
        (["limits", "--obliquities", "45", "--tolerance", "1e-14"], "[2e-10, 1950] m/s"),
        (["limits", "--obliquities", "45", "--tolerance", "1e-300"], "[2e-10, 1950] m/s"),
        (["limits", "--obliquities", "45", "--speeds", "50:100", "--tolerance", "1e-12"],
         "[1e-11, 50] m/s"),
        (["limits", "--speeds", "300", "--tolerance", "1e-14"], "[8.9e-12, 89] deg"),
        (["limits", "--speeds", "300", "--tolerance", "1e-3", "--resolution", "1e-4"],
         "--resolution: resolution must be in [0.001,"),
        (["map", "--tolerance", "1e-14", "--png", "m.png"], "[2e-10, 9.79899] m/s"),
        (["map", "--tolerance", "1e-300", "--png", "m.png"], "--tolerance: tolerance must be"),
        (["map", "--tolerance", "inf", "--png", "m.png"], "[2e-10, 9.79899] m/s"),
        (["limits", "--obliquities", "45", "--resolution", "nan"], "[0.01, 1950] m/s"),
        (["limits", "--obliquities", "45", "--resolution", "inf"], "[0.01, 1950] m/s"),
    ],
)  # fmt: skip
def test_the_command_line_names_the_tolerance_and_its_range(argv, named, scenes_run):
    code, _, err = run_cli([*argv, "--preset", "2024-T3/1.27"])
    flag = "--resolution" if "--resolution" in argv else "--tolerance"
    assert_one_line(code, err, f"{flag}: ", named)
    assert scenes_run == [0]


def test_a_tolerance_at_the_floor_is_reached():
    """A boundary at 1999.9999999 m/s on 0-2000 m/s, located to the floor (2e-10 m/s:
    about 450 ulps there) in a bounded number of passes."""
    edge = 1999.9999999
    tolerance = finder.finest_tolerance(np.array([0.0]), np.array([2000.0]))
    found = finder.locate(
        lambda line, x: (x >= edge).astype(np.int64), np.array([0.0]), np.array([2000.0]),
        1.0, tolerance,
    )  # fmt: skip
    assert found.low[0] < edge <= found.high[0]
    assert found.high[0] - found.low[0] <= tolerance
    assert found.passes <= finder.MAX_PASSES


def test_a_refinement_that_cannot_shrink_ends_in_one_line_not_a_loop(monkeypatch):
    """Belt and braces: with the floor lifted, a tolerance below one ulp makes cuts that
    coincide; the finder says so after a bounded number of evaluations instead of
    looping (the old finder evaluated the same points for ever)."""
    monkeypatch.setattr(finder, "RELATIVE_FLOOR", 0.0, raising=False)
    calls = [0]

    def evaluate(line: np.ndarray, x: np.ndarray) -> np.ndarray:
        calls[0] += 1
        if calls[0] > 10 * finder.MAX_PASSES:
            raise AssertionError("the finder is looping")
        return (x >= 184.6252241511).astype(np.int64)

    with pytest.raises(pi.ParameterError) as info:
        finder.locate(evaluate, np.array([50.0]), np.array([2000.0]), 1.0, 1e-300)
    assert info.value.parameter == "tolerance" and "did not shrink" in str(info.value)
    assert calls[0] <= finder.MAX_PASSES + 1
