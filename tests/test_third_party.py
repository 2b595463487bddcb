"""A third-party resistance law with its own plate constant and setting, through every
door a user has: Python, the command line (--set and its declared flag), a plate file,
and a study archive with resume. The core knows nothing of either; see
tests/third_party/plateimpact_isotropic."""

from __future__ import annotations

import json
import os
import subprocess
import sys

import attrs
import h5py
import numpy as np
import pytest
from conftest import THIRD_PARTY
from scipy.integrate import solve_ivp
from test_output_files import run_cli as run_in_process

import plateimpact as pi
from plateimpact import presets
from plateimpact.storage.plate_file import load_plate_file, plate_file_text

SPHERE = presets.DEFAULT_SPHERE
PLATE = presets.plate("6061-T6/9.53")
SENSITIVE = attrs.evolve(PLATE, rate_sensitivity=0.3)


def rate_simulation(registry, failure="intact", rtol=1e-10, **settings):
    """The rate law with its ``settings``, at ``rtol`` (1e-10 for the closed form's 1e-7)."""
    return pi.Simulation.from_names(
        "rate-poncelet",
        failure,
        integrator_settings={"rtol": rtol},
        resistance_settings=settings,
        registry=registry,
    )


def test_without_its_constant_the_law_is_eq_1_to_the_last_bit(with_third_party):
    # c defaults to 0, where a (1 + c ln(...)) is a exactly: the report's law, bit for bit
    # (on the numpy path, where the rate law, which has no kernels, runs).
    registry = pi.load_registry()
    rng = np.random.default_rng(2)
    batch = pi.SceneBatch.grid(SPHERE, PLATE, rng.uniform(100, 1500, 12), np.radians([0, 45, 70]))
    report = pi.Simulation.from_names(registry=registry, engine="numpy").run_batch(batch)
    rate = pi.Simulation.from_names("rate-poncelet", registry=registry).run_batch(batch)
    for name, column in report.columns.items():
        np.testing.assert_array_equal(rate.columns[name], column, err_msg=name)


def closed_form_depth(speed, c, reference_speed, rest_fraction=0.01):
    """Rest depth at normal incidence on an intact plate, integrated independently of the
    model: m V dV = −A(P) σ(V) dP with A = π(2 Rs P − P²) (P <= Rs), solved for P(V)."""
    rs, m, a, b = SPHERE.radius, SPHERE.mass, PLATE.a, PLATE.b

    def sigma(v):
        return a * (1 + c * np.log1p(v / reference_speed)) + b * v * v

    def dp_dv(v, p):
        area = np.pi * max(2 * rs * p[0] - p[0] ** 2, 1e-30)
        return [-m * v / (area * sigma(v))]

    # Start a hair in, from the series P ≈ (m Vs² ... ) of the first contact: A ≈ 2π Rs P.
    v0 = speed * (1 - 1e-9)
    p0 = np.sqrt(m * (speed**2 - v0**2) / (2 * np.pi * rs * sigma(speed)))
    solution = solve_ivp(dp_dv, (v0, rest_fraction * speed), [p0], rtol=1e-12, atol=1e-15)
    return solution.y[0, -1]


def test_its_constant_and_setting_reach_the_law(with_third_party):
    registry = pi.load_registry()
    simulation = rate_simulation(registry, reference_speed=50.0)
    result = simulation.run(pi.Scene(SPHERE, SENSITIVE, 200.0, 0.0))
    expected = closed_form_depth(200.0, 0.3, 50.0)
    assert result.max_penetration < SPHERE.radius  # the closed form's range
    assert result.max_penetration == pytest.approx(expected, rel=1e-7)
    plain = rate_simulation(registry).run(pi.Scene(SPHERE, PLATE, 200.0, 0.0))
    assert plain.max_penetration > result.max_penetration  # a stronger plate
    with pytest.raises(pi.ParameterError, match="rate_sensitivity must be >= 0"):
        simulation.run(pi.Scene(SPHERE, attrs.evolve(PLATE, rate_sensitivity=-1.0), 200.0, 0.0))


def run_cli(*args, check=True):
    """The command in a new interpreter that finds the package on its PYTHONPATH, as a
    user's shell does: its exit code and start-up are what these runs check."""
    env = {**os.environ, "PYTHONPATH": os.pathsep.join([str(THIRD_PARTY), *sys.path])}
    command = [sys.executable, "-m", "plateimpact.cli", *args]
    return subprocess.run(command, capture_output=True, text=True, env=env, check=check)


def run_here(*args: str) -> str:
    """What the command prints, run in this process (the package installed by the
    ``with_third_party`` fixture): the same parsing, registry and output as run_cli's,
    without an interpreter's start-up for each of many runs."""
    code, out, err = run_in_process(list(args))
    assert code == 0, err
    return out


def test_from_the_command_line_set_and_the_declared_flag_match_python(with_third_party, tmp_path):
    registry = pi.load_registry()
    # The default rtol: Python and each command line run the same settings, to the bit.
    expected = rate_simulation(registry, "plugging", 1e-8, reference_speed=50.0).run(
        pi.Scene(SPHERE, SENSITIVE, 700.0, np.radians(30.0))
    )
    base = ["run", "--preset", "6061-T6/9.53", "--speed", "700", "--obliquity", "30", "--json"]
    model = ["--resistance", "rate-poncelet", "--set", "integrator.rtol=1e-8"]
    ways = [
        ["--set", "resistance.rate_sensitivity=0.3", "--set", "resistance.reference_speed=50"],
        ["--set", "resistance.c=0.3", "--set", "resistance.reference_speed=50"],
        ["--c", "0.3", "--set", "resistance.reference_speed=50"],
        ["--set", "plate.rate_sensitivity=0.3", "--set", "resistance.reference_speed=50"],
    ]
    for way in ways:
        out = json.loads(run_here(*base, *model, *way))
        assert out["outcome"] == expected.outcome.label
        assert out["exit_speed_m_s"] == expected.exit_speed
        assert out["model"]["resistance_settings"] == {"reference_speed": 50.0}
    plate_file = tmp_path / "plate.json"
    plate_file.write_text(plate_file_text(SENSITIVE, registry=registry))
    assert json.loads(plate_file.read_text())["c"] == 0.3
    assert load_plate_file(plate_file, registry) == SENSITIVE
    file_run = ["run", "--plate-file", str(plate_file), *base[3:], *model]
    out = json.loads(run_cli(*file_run, "--set", "resistance.reference_speed=50").stdout)
    assert out["exit_speed_m_s"] == expected.exit_speed
    # The constant belongs to its law: with the report's law it is refused, by its flag.
    # (In this process: a new interpreter's exit code on a refusal is checked below, for
    # the failure model's setting.)
    code, _, err = run_in_process([*base, "--c", "0.3"])
    assert code == 2 and err.startswith("plateimpact: error: --c:")
    code, _, err = run_in_process([*base, *model, "--set", "resistance.rate_sensitivity=-2"])
    assert code == 2
    assert "--set resistance.rate_sensitivity: rate_sensitivity must be >= 0" in err


def test_in_a_study_archive_with_resume(with_third_party, tmp_path):
    registry = pi.load_registry()
    variant = pi.Variant(
        "rate", resistance="rate-poncelet", resistance_settings={"reference_speed": 50.0}
    )
    study = pi.Study.grid("rate", [SENSITIVE], [0, 45], np.linspace(200, 900, 5), variant)
    path = tmp_path / "a.h5"
    results = study.run(archive=path, registry=registry)
    archive = pi.Archive(path)
    meta = archive.metadata("rate")
    assert meta["model"]["resistance_settings"] == {"reference_speed": 50.0}
    assert meta["variant"]["resistance_settings"] == {"reference_speed": 50.0}
    with h5py.File(path, "r") as f:  # the constant is a scene column, described
        column = f["rate/scenes/rate_sensitivity"]
        assert column.attrs["units"] == "1" and "rate sensitivity" in column.attrs["description"]
        np.testing.assert_array_equal(column[()], 0.3)
    back = pi.Study.from_archive(path)
    np.testing.assert_array_equal(back.scenes.rate_sensitivity, 0.3)
    again = back.run(archive=path, resume=True, registry=registry)
    assert archive.runs() == ["rate/rate"]  # read back, not run again
    np.testing.assert_array_equal(again["rate"].exit_speed, results["rate"].exit_speed)


def test_a_constant_declared_two_ways_is_refused(with_third_party):
    registry = pi.load_registry()
    other = attrs.evolve(pi.load_registry().plate_constants["a"], description="something else")
    impostor = type(
        "Impostor",
        (pi.ResistanceLaw,),
        {"name": "impostor", "plate_constants": (other,), "stress": None},
    )
    with pytest.raises(
        pi.PluginError, match="declares plate constant 'a' unlike resistance poncelet"
    ):
        registry.add(impostor)


def brittle_rk4(registry):
    """The package's failure model and integrator, each with a setting: a step five
    times the default's, coarse because these tests follow the settings through each
    door, not rk4's accuracy (test_docs measures its order); the scenes keep their
    outcomes at it."""
    return pi.Simulation.from_names(
        failure="brittle",
        integrator="rk4",
        failure_settings={"residual_resistance": 0.25},
        integrator_settings={"step": 0.05},
        registry=registry,
    )


def test_its_failure_model_and_integrator_from_the_command_line_and_a_plate_file(
    with_third_party, tmp_path
):
    registry = pi.load_registry()
    plate = attrs.evolve(PLATE, critical_penetration=2e-3)
    expected = brittle_rk4(registry).run(pi.Scene(SPHERE, plate, 900.0, np.radians(20.0)))
    assert expected.plate_failed and expected.outcome == pi.Outcome.PERFORATION
    plate_file = tmp_path / "plate.json"
    plate_file.write_text(plate_file_text(plate, registry=registry))
    model = ["--failure", "brittle", "--set", "failure.residual_resistance=0.25"]
    model += ["--integrator", "rk4", "--set", "integrator.step=0.05"]
    scene = ["--speed", "900", "--obliquity", "20", "--json"]
    for source in (
        ["--preset", "6061-T6/9.53", "--pstar", "2"],
        ["--plate-file", str(plate_file)],
    ):
        out = json.loads(run_here("run", *source, *scene, *model))
        assert out["outcome"] == "perforation"
        assert out["exit_speed_m_s"] == expected.exit_speed
        assert out["model"]["failure"] == "brittle"
        assert out["model"]["failure_settings"] == {"residual_resistance": 0.25}
        assert out["model"]["integrator_settings"]["step"] == 0.05
    bad = run_cli(
        "run",
        "--preset",
        "6061-T6/9.53",
        *scene,
        *model[:2],
        "--set",
        "failure.residual_resistance=2",
        check=False,
    )
    assert (
        bad.returncode == 2
        and "--set failure.residual_resistance: residual_resistance must be in [0, 1]" in bad.stderr
    )


def test_its_failure_model_and_integrator_in_a_study_archive_with_resume(
    with_third_party, tmp_path
):
    registry = pi.load_registry()
    variant = pi.Variant(
        "brittle",
        failure="brittle",
        integrator="rk4",
        failure_settings={"residual_resistance": 0.25},
        integrator_settings={"step": 0.05},
    )
    plate = attrs.evolve(PLATE, critical_penetration=2e-3)
    study = pi.Study.grid("brittle", [plate], [0, 30], np.linspace(400, 1200, 4), variant)
    path = tmp_path / "a.h5"
    results = study.run(archive=path, registry=registry)
    meta = pi.Archive(path).metadata("brittle")
    assert meta["model"]["failure"] == "brittle" and meta["model"]["integrator"] == "rk4"
    assert meta["variant"]["failure_settings"] == {"residual_resistance": 0.25}
    again = pi.Study.from_archive(path).run(archive=path, resume=True, registry=registry)
    assert pi.Archive(path).runs() == ["brittle/brittle"]  # read back, not run again
    np.testing.assert_array_equal(again["brittle"].exit_speed, results["brittle"].exit_speed)
    direct = brittle_rk4(registry).run_batch(study.scenes)
    np.testing.assert_array_equal(results["brittle"].exit_speed, direct.exit_speed)
