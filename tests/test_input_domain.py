"""The input domain and the work bounds (docs/robustness.md, "the input domain").

Every numeric input has a physical range: outside it the command line prints one line
naming the flag the user typed and the range, writes nothing and exits 2, and the Python
API raises ParameterError. Inside it no RuntimeWarning reaches the user. Every integrator
has a work bound (max_steps, max_seconds) that ends a run with one line naming the setting.
"""

from __future__ import annotations

import math
import warnings
from pathlib import Path

import numpy as np
import pytest

import plateimpact as pi
from plateimpact import presets
from plateimpact.cli import main
from plateimpact.solve import driver
from plateimpact_plugins import report
from plateimpact_plugins.report.ab_start import log_domain

SPHERE = presets.DEFAULT_SPHERE
PLATE = presets.plate("2024-T3/3.18")
RUN = ["run", "--preset", "2024-T3/3.18", "--speed", "500", "--obliquity", "30"]
CRATER = ["crater", "--preset", "2024-T3/3.18", "--speed", "500", "--obliquity", "30"]
SWEEP = ["sweep", "--preset", "2024-T3/3.18", "--speeds", "500", "--obliquities", "30"]
SHOTS = Path(__file__).resolve().parents[1] / "studies" / "data" / "shots_2024T3_3.18mm.csv"
CALIBRATE = ["calibrate", str(SHOTS), "--thickness", "3.18", "--pstar", "3", "--alpha", "45"]


def replaced(args: list[str], flag: str, value: str) -> list[str]:
    """``args`` with the value after ``flag`` replaced."""
    at = args.index(flag) + 1
    return [*args[:at], value, *args[at + 1 :]]


# (command line, what the one line must name). Each quoted case of issue 15 is here.
BAD_COMMAND_LINES = [
    (replaced(RUN, "--speed", "1e200"), "--speed: impact_speed must be in [0.001, 10000] m/s"),
    (replaced(RUN, "--speed", "1e-300"), "--speed: impact_speed must be in"),
    (replaced(RUN, "--speed", "1e400"), "--speed: impact_speed must be in"),
    ([*replaced(RUN, "--speed", "1e200"), "--integrator", "segment"], "--speed: "),
    ([*replaced(RUN, "--speed", "1e200"), "--integrator", "solve_ivp"], "--speed: "),
    ([*RUN, "--radius", "1e-300"], "--radius: radius must be in [0.001, 1000] mm"),
    ([*RUN, "--mass", "1e-300"], "--mass: mass must be in"),
    ([*RUN, "--radius", "0.001", "--mass", "1"], "--mass: mass 1 g on radius 0.001 mm"),
    ([*RUN, "--a", "1e300"], "--a: a must be in [100000, 1e+11] N/m^2"),
    ([*RUN, "--b", "1e300"], "--b: b must be in [0, 100000] kg/m^3"),
    ([*RUN, "--pstar", "1e-300"], "--pstar: critical_penetration must be >= 1e-06 mm"),
    ([*RUN, "--thickness", "1e300"], "--thickness: thickness must be in"),
    ([*RUN, "--set", "plate.a=1e300"], "--set plate.a: a must be in"),
    ([*RUN, "--integrator", "segment", "--step", "1e-9"], "--step: step must be in [1e-05, 0.1]"),
    ([*RUN, "--rtol", "1e-300"], "--rtol: rtol must be in [1e-13, 0.01]"),
    ([*RUN, "--set", "integrator.fixed_step=1e-9"], "--set integrator.fixed_step: "),
    ([*RUN, "--set", "integrator.max_steps=1e400"], "--set integrator.max_steps: "),
    ([*RUN, "--set", "integrator.max_seconds=0"], "--set integrator.max_seconds: "),
    ([*RUN, "--set", "model.rest_speed_fraction=1e-300"], "--set model.rest_speed_fraction: "),
    (
        [*RUN, "--failure", "hinge", "--set", "failure.finger_area_scale=1e300"],
        "--set failure.finger_area_scale: finger_area_scale must be in [0, 10]",
    ),
    (replaced(SWEEP, "--speeds", "inf:1:2"), "--speeds: impact_speed must be in"),
    (replaced(SWEEP, "--speeds", "1:1e200:3"), "--speeds: impact_speed must be in"),
    (replaced(SWEEP, "--speeds", "100,1e200"), "--speeds: impact_speed must be in"),
    (replaced(SWEEP, "--speeds", "1:2:99999999999"), "--speeds: N must be <= 10,000,000"),
    (replaced(SWEEP, "--obliquities", "nan"), "--obliquities: impact_obliquity must be in"),
    ([*SWEEP, "--mass", "1e-300"], "--mass: "),
    (replaced(CRATER, "--speed", "1e200"), "--speed: "),
    ([*CRATER, "--radius", "1e-300"], "--radius: "),
    ([*CALIBRATE, "--radius", "1e-300"], "--radius: "),
    ([*CALIBRATE, "--mass", "1e-300"], "--mass: "),
    ([*CALIBRATE, "--rtol", "1e-300"], "--rtol: "),
    ([*CALIBRATE, "--integrator", "segment", "--step", "1e-9"], "--step: "),
    (replaced(CALIBRATE, "--pstar", "1e-300"), "--pstar: "),
]
#: The output option of each command, pointed into the test's directory.
OUTPUTS = {
    "run": ["--trajectory", "path.csv"],
    "crater": ["--csv", "crater.csv", "--png", "crater.png"],
    "sweep": ["--csv", "sweep.csv"],
    "calibrate": ["--out", "plate.json", "--png", "fit.png"],
}


def one_error_line(args: list[str], capsys: pytest.CaptureFixture[str]) -> str:
    """Run the command in-process with every RuntimeWarning an error; its one error line."""
    with warnings.catch_warnings():
        warnings.simplefilter("error", RuntimeWarning)
        code = main(args)
    captured = capsys.readouterr()
    assert code == 2, captured
    assert captured.err.count("\n") == 1 and captured.err.startswith("plateimpact: error: ")
    return captured.err


@pytest.mark.parametrize(("args", "named"), BAD_COMMAND_LINES)
def test_bad_command_lines_name_the_typed_flag_and_write_nothing(
    args, named, tmp_path, monkeypatch, capsys
):
    monkeypatch.chdir(tmp_path)
    err = one_error_line([*args, *OUTPUTS[args[0]]], capsys)
    assert named in err, err
    assert list(tmp_path.iterdir()) == []


def test_shots_outside_the_speed_range_are_refused_by_file_line_and_column(tmp_path, capsys):
    shots = tmp_path / "shots.csv"
    shots.write_text(
        "impact_speed_m_s,impact_obliquity_deg,residual_speed_m_s\n"
        "900,0,500\n20000,0,15000\n1000,0,600\n1100,0,700\n"
    )
    err = one_error_line(["calibrate", str(shots), *CALIBRATE[2:]], capsys)
    assert "impact_speed_m_s" in err and "in [0.001, 10000] m/s" in err and "20000" in err


@pytest.mark.parametrize(
    ("rows", "named"),
    [
        # Issue 15: speeds near 1e300 overflowed Vs² inside the fit (a traceback).
        (["1e300,0,5e299", "2e300,0,1e300", "3e300,0,2e300"], "line 2, column impact_speed_m_s"),
        # Three shots within 2e-7 m/s: Eq 41's line through (Vs², Vr²) has no slope.
        (
            ["500,0,300", "500.0000001,0,300.0000001", "500.0000002,0,300.0000002"],
            "perforating shots at different impact speeds",
        ),
    ],
)
def test_calibration_shots_that_fix_no_fit_are_one_line(rows, named, tmp_path, capsys):
    shots = tmp_path / "shots.csv"
    shots.write_text("impact_speed_m_s,impact_obliquity_deg,residual_speed_m_s\n" + "\n".join(rows))
    argv = ["calibrate", str(shots), *CALIBRATE[2:], "--out", str(tmp_path / "p.json")]
    err = one_error_line(argv, capsys)
    assert named in err, err
    assert sorted(p.name for p in tmp_path.iterdir()) == ["shots.csv"]


# -- the work bounds -------------------------------------------------------------------


class Clock:
    """A fake ``time`` module for the driver: each read of the clock advances it by
    ``seconds`` (a machine as slow as we like, deterministically); ``reads`` counts them."""

    def __init__(self, seconds: float) -> None:
        self.seconds, self.now, self.reads = seconds, 0.0, 0

    def perf_counter(self) -> float:
        self.reads += 1
        self.now += self.seconds
        return self.now


def test_where_a_scene_ends_never_depends_on_the_clock(monkeypatch, capsys):
    """By default no wall-time bound is armed: on a machine so slow that every pass of
    the step loop takes an hour, results are bit for bit the same and a scene that needs
    more work than max_steps ends with the same line naming max_steps."""
    batch = pi.SceneBatch.grid(SPHERE, PLATE, [300.0, 640.0, 1200.0], np.radians([0.0, 60.0]))
    integrators = {"dopri5": {}, "segment": {"step": 1e-2}, "solve_ivp": {"rtol": 1e-8}}
    quick = {n: pi.Simulation.from_names(integrator=n, integrator_settings=s)
             for n, s in integrators.items()}  # fmt: skip
    expected = {n: simulation.run_batch(batch) for n, simulation in quick.items()}
    bounded = [*RUN, "--set", "integrator.max_steps=7"]
    fast = one_error_line(bounded, capsys)
    slow = Clock(3600.0)
    monkeypatch.setattr(driver, "time", slow)
    for name, simulation in quick.items():
        result = simulation.run_batch(batch)
        for column, values in expected[name].columns.items():
            np.testing.assert_array_equal(result.columns[column], values, err_msg=column)
    assert one_error_line(bounded, capsys) == fast
    assert "unfinished after max_steps=7 steps" in fast and slow.reads == 0
    assert all(s.default is None for s in [pi.MAX_SECONDS, *max_seconds_declarations()])


def test_the_opt_in_wall_time_bound_ends_a_run_with_one_line_naming_its_flag(monkeypatch, capsys):
    """max_seconds, when a user sets it, is charged per scene on the clock: with a clock
    that advances 1 s a read it fires at the pass that takes a scene past the limit."""
    clock = Clock(1.0)
    monkeypatch.setattr(driver, "time", clock)
    err = one_error_line([*RUN, "--set", "integrator.max_seconds=2.5"], capsys)
    assert "dopri5: 1 scene(s) unfinished after max_seconds=2.5 s of wall time" in err
    assert "after 2 steps" in err  # charged 1 s per pass: over 2.5 s at the 3rd
    assert "raise max_seconds (--set integrator.max_seconds=SECONDS)" in err
    assert clock.reads == 4


def test_a_sphere_sliding_on_a_plate_that_never_holds_it_is_refused_by_its_steps(capsys):
    """The first slowest scene of docs/robustness.md: P* = 1 nm fails the plate at first
    contact, and at 89.999 deg the sphere must slide about 2 Rs / cos(89.999 deg) =
    1.1e5 Rs at nearly its impact speed before it is through. dopri5's steps are at most
    0.5 Rs/Vs, so it needs more than 2e5 steps: the default bound ends it, by count."""
    scene = ["run", "--preset", "2024-T3/3.18", "--speed", "10000", "--obliquity", "89.999",
             "--pstar", "1e-6"]  # fmt: skip
    err = one_error_line([*scene, "--set", "integrator.max_steps=400"], capsys)
    progress = err.split("(first: scene 0, at ")[1].split(" after ")[0]
    depth, speed, time = (float(part.split(" = ")[1].split()[0]) for part in progress.split(", "))
    assert depth < 0.1 and speed == 1.0 and 0.9 * 200.0 < time <= 200.0  # <= 0.5 Rs/Vs a step
    slide = 2.0 / math.cos(math.radians(89.999))
    assert slide / 0.5 > pi.MAX_STEPS.default


@pytest.mark.parametrize("integrator", ["dopri5", "segment", "solve_ivp"])
def test_the_step_bound_says_where_the_scene_got_to(integrator, capsys):
    args = [*RUN, "--integrator", integrator, "--set", "integrator.max_steps=3"]
    err = one_error_line(args, capsys)
    assert f"{integrator}: 1 scene(s) unfinished after max_steps=3 steps" in err
    assert "(first: scene 0, at P = " in err and "after 3 steps" in err
    assert "raise max_steps (--set integrator.max_steps=N)" in err


def test_solve_ivps_end_time_is_a_setting_its_message_names(capsys):
    # This contact lasts about 4 Rs/Vs (25 us; Rs/Vs = 6.35 us): a phase outlasts 1 Rs/Vs.
    args = [*RUN, "--integrator", "solve_ivp", "--set", "integrator.longest_phase=1"]
    err = one_error_line(args, capsys)
    assert "solve_ivp: a scene unfinished after longest_phase=1 Rs/Vs" in err
    assert "(--set integrator.longest_phase=MULTIPLE)" in err
    assert main([*RUN, "--integrator", "solve_ivp"]) == 0


def test_every_builtin_integrator_declares_both_work_bounds():
    registry = pi.load_registry()
    for name in registry.names("integrator"):
        settings = registry.get("integrator", name).setting_declarations()
        assert {"max_steps", "max_seconds"} <= set(settings), name
        assert settings["max_seconds"].default is pi.MAX_SECONDS.default is None
    # An integrator that declares neither keeps the base class's: the same bounds.
    assert (pi.Integrator.max_steps, pi.Integrator.max_seconds) == (pi.MAX_STEPS.default, None)


def max_seconds_declarations() -> list[pi.Parameter]:
    registry = pi.load_registry()
    return [
        registry.get("integrator", name).setting_declarations()["max_seconds"]
        for name in registry.names("integrator")
    ]


def test_the_wall_time_bound_in_the_api_is_an_integration_error(monkeypatch):
    monkeypatch.setattr(driver, "time", Clock(1.0))
    simulation = pi.Simulation.from_names(integrator_settings={"max_seconds": 0.5})
    batch = pi.SceneBatch.grid(SPHERE, PLATE, [300.0, 600.0], [0.0])
    with pytest.raises(pi.IntegrationError, match=r"2 scene\(s\) unfinished after max_seconds"):
        simulation.run_batch(batch)
    unbounded = pi.Simulation.from_names(integrator_settings={"max_seconds": math.inf})
    assert unbounded.run_batch(batch).outcome.size == 2


# -- the Python API --------------------------------------------------------------------

BAD_API_INPUT = [
    (lambda: pi.Sphere(radius=1e300, mass=1e-3), "radius"),
    (lambda: pi.Sphere(radius=10**400, mass=1e-3), "radius"),
    (lambda: pi.Sphere(radius=1e-3, mass=10**400), "mass"),
    (lambda: pi.Sphere(radius=1e-3, mass=1.0), "mass"),  # 2.4e5 kg/m^3
    (lambda: pi.Sphere.of_density(1e300, 7830.0), "radius"),  # was OverflowError
    (lambda: pi.Sphere.of_density(1e-3, 1e308), "density"),
    (lambda: pi.Plate(3, 1e-3), "material"),  # was TypeError
    (lambda: pi.Plate("m", 1e-3, constants=5), "constants"),  # was TypeError
    (lambda: pi.Plate("m", 1e-3, a=10**400), "a"),  # was OverflowError
    (lambda: pi.Scene("sphere", PLATE, 100.0, 0.0), "sphere"),  # was TypeError
    (lambda: pi.Scene(SPHERE, None, 100.0, 0.0), "plate"),  # was TypeError
    (lambda: pi.Scene(SPHERE, PLATE, 10**400, 0.0), "impact_speed"),  # was OverflowError
    (lambda: pi.Scene(SPHERE, PLATE, 1e200, 0.0), "impact_speed"),
    (lambda: pi.SceneBatch(5), "columns"),  # was AttributeError
    (lambda: pi.SceneBatch({"radius": "abc"}), "radius"),  # was ValueError
    (lambda: pi.SceneBatch({"radius": [[1.0, 2.0], [3.0]]}), "radius"),  # was ValueError
    (lambda: pi.SceneBatch.grid(SPHERE, PLATE, "fast", [0.0]), "impact_speed"),
    (lambda: pi.SceneBatch.grid("sphere", PLATE, [100.0], [0.0]), "sphere"),
    (lambda: pi.SceneBatch.from_scenes([1]), "scene 0"),  # was AttributeError
    (lambda: pi.Simulation.from_names(integrator_settings=5), "integrator_settings"),
    (lambda: pi.Simulation.from_names(integrator_settings={"max_steps": math.inf}), "max_steps"),
    (lambda: pi.Simulation.from_names(integrator_settings={"rtol": 1e-300}), "rtol"),
    (lambda: pi.Variant("v", integrator_settings=5), "settings"),  # was TypeError
]


@pytest.mark.parametrize(("build", "parameter"), BAD_API_INPUT)
def test_bad_api_input_raises_parameter_error(build, parameter):
    with pytest.raises(pi.ParameterError) as info:
        build()
    assert info.value.parameter == parameter
    assert "\n" not in str(info.value) and len(str(info.value)) < 300


def test_a_batch_checks_the_density_of_each_scene():
    columns = {
        "radius": [1e-3, 1e-3],
        "mass": [4e-5, 1.0],
        "thickness": [3e-3, 3e-3],
        "impact_speed": [300.0, 300.0],
        "impact_obliquity": [0.0, 0.0],
    }
    with pytest.raises(pi.ParameterError, match=r"density must be in .*\(scene 1\)"):
        pi.SceneBatch(columns)


def test_spheres_at_the_ends_of_both_ranges_are_accepted():
    for radius in (1e-6, 1.0):
        for density in (100.0, 25_000.0):
            assert pi.Sphere.of_density(radius, density).radius == radius


def test_the_property_tests_domain_lies_inside_the_ranges():
    # tests/test_properties.py draws radius 0.5-20 mm, density 1-20 g/cm^3, speed 1 m/s-
    # 5 km/s, a 3e7-3e10, b 30-3e4, P* and thickness 0.1-10 Rs.
    for radius in (0.5e-3, 20e-3):
        for density in (1000.0, 20_000.0):
            sphere = pi.Sphere.of_density(radius, density)
            for speed in (1.0, 5000.0):
                plate = pi.Plate("p", 0.1 * radius, a=3e7, b=3e4, critical_penetration=10 * radius)
                pi.SceneBatch.from_scenes([pi.Scene(sphere, plate, speed, 0.0)])
    simulation = pi.Simulation.from_names()
    grid = pi.SceneBatch.grid(SPHERE, PLATE.with_constants(a=3e10, b=30.0), [1.0], [0.0])
    simulation.model.bind(grid)


# -- no RuntimeWarning inside the domain -----------------------------------------------

#: Corners of the domain that finish in a few steps: the stiffest (a micrometre balsa
#: sphere at 1 mm/s into the strongest plate) and the softest that still stop soon.
CORNERS = [
    # radius, density, speed, obliquity [deg], a, b, P*, alpha* [deg]
    (1e-6, 100.0, 1e-3, 45.0, 1e11, 1e5, 1e-9, 1e-6),
    (1e-6, 100.0, 1e-3, 0.0, 1e11, 1e5, math.inf, 89.9999),
    (1e-6, 25_000.0, 1e-3, 45.0, 1e5, 0.0, 1e-9, 89.0),
    (1.0, 100.0, 1e4, 45.0, 1e11, 1e5, 1e-9, 45.0),
    (1.0, 25_000.0, 1e4, 89.999, 1e11, 1e5, 1e-3, 45.0),
]


@pytest.mark.parametrize(
    ("integrator", "settings"),
    [("dopri5", {}), ("segment", {"step": 0.1}), ("solve_ivp", {"method": "RK45"})],
)
def test_corners_of_the_domain_run_without_runtime_warnings(integrator, settings):
    columns: dict[str, list[float]] = {}
    for radius, density, speed, obliquity, a, b, pstar, alpha in CORNERS:
        row = {
            "radius": radius,
            "mass": pi.Sphere.of_density(radius, density).mass,
            "thickness": 1e-3,
            "impact_speed": speed,
            "impact_obliquity": math.radians(obliquity),
            "a": a,
            "b": b,
            "critical_penetration": pstar,
            "failure_angle": math.radians(alpha),
        }
        for name, value in row.items():
            columns.setdefault(name, []).append(value)
    simulation = pi.Simulation.from_names(integrator=integrator, integrator_settings=settings)
    with warnings.catch_warnings():
        warnings.simplefilter("error", RuntimeWarning)
        result = simulation.run_batch(pi.SceneBatch(columns), record_trajectory=True)
    assert np.all(np.isin(result.outcome, [int(o) for o in pi.Outcome]))
    assert np.all(np.isfinite(result.exit_speed))


@pytest.mark.parametrize("fit", [report.newton_fit, report.direct_fit])
def test_calibration_never_runs_the_model_outside_its_range(fit):
    shots = pi.Shots.from_csv(SHOTS)
    with pytest.raises(pi.CalibrationError, match=r"start a = 1 N/m\^2.*outside the model's"):
        fit(shots, PLATE, start=(1.0, 1000.0))
    low, high = log_domain(pi.Simulation.from_names())
    np.testing.assert_allclose(np.exp([low[0], high[0], high[1]]), [1e5, 1e11, 1e5])
    assert low[1] == -math.inf  # b may be 0: no lower bound on ln b
