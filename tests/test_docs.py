"""docs/plugins.md is code: its blocks run (tests/conftest.py, ``docs_plugins``) and what
they define behaves as the page says."""

from __future__ import annotations

import re
from pathlib import Path

import numpy as np
import pytest
from test_integrators import closed_form_rest_depth

import plateimpact as pi
from plateimpact import presets

ROOT = Path(__file__).resolve().parents[1]
SPHERE = presets.DEFAULT_SPHERE


PACKAGE = ROOT / "tests" / "third_party" / "plateimpact_isotropic"


def blocks() -> list[str]:
    return re.findall(r"```python\n(.*?)```", (ROOT / "docs" / "plugins.md").read_text(), re.S)


def block_defining(name: str) -> str:
    return next(b for b in blocks() if f"class {name}(" in b)


def lines_in_order(block: str, module: str) -> bool:
    """Every line of ``block`` is a line of ``module``, in the same order (the module may
    have more: its own docstring, its relative imports)."""
    remaining = iter(module.splitlines())
    return all(any(line == other for other in remaining) for line in block.splitlines())


@pytest.mark.parametrize(
    "name, module",
    [
        ("RatePoncelet", "__init__.py"),
        ("IsotropicPoncelet", "__init__.py"),
        ("Brittle", "brittle.py"),
        ("ClassicalRungeKutta", "rk4.py"),
    ],
)
def test_the_pages_plug_ins_are_the_third_party_packages_code_and_short(name, module):
    block = block_defining(name)
    assert lines_in_order(block, (PACKAGE / module).read_text())
    assert len(block.splitlines()) < 60  # each one shown complete, under 60 lines


def test_the_pages_registration_is_the_packages_hook():
    hook = next(b for b in blocks() if "def plateimpact_register" in b)
    assert lines_in_order(hook, (PACKAGE / "__init__.py").read_text())


def test_the_pages_usage_example_ran_with_the_rate_constant(docs_plugins):
    # The example's plate has c = 0.3: a strength term that grows with speed stops the
    # sphere sooner than eq 1 alone (c = 0) on the same plate.
    result = docs_plugins["result"]
    plain = pi.Simulation.from_names().run(
        pi.Scene(SPHERE, presets.plate("6061-T6/9.53"), 700.0, np.radians(30.0))
    )
    assert result.outcome == plain.outcome
    assert result.max_penetration < 0.95 * plain.max_penetration


def brittle(registry, residual):
    return pi.Simulation.from_names(
        failure="brittle", failure_settings={"residual_resistance": residual}, registry=registry
    )


def test_the_pages_failure_model_with_all_its_resistance_changes_nothing(docs_registry):
    # r = 1: the force is the intact one throughout, so the sphere stops where it stops on
    # an intact plate (to the step control's tolerance: the onset event restarts the
    # steps), as long as it stops before its back face would let it out.
    plate = presets.plate("6061-T6/9.53").with_constants(critical_penetration=1e-3)
    batch = pi.SceneBatch.grid(SPHERE, plate, [300.0, 500.0, 700.0], np.radians([0.0, 30.0]))
    kept = brittle(docs_registry, 1.0).run_batch(batch)
    intact = pi.Simulation.from_names(failure="intact", registry=docs_registry).run_batch(batch)
    assert kept.plate_failed.all()  # every scene passed P* = 1 mm
    assert intact.max_penetration.max() < plate.thickness + 2 * SPHERE.radius
    np.testing.assert_array_equal(kept.outcome, intact.outcome)
    np.testing.assert_allclose(kept.max_penetration, intact.max_penetration, rtol=1e-6)


def test_the_pages_failure_model_with_no_resistance_left_flies_straight_on(docs_registry):
    # r = 0: no force after onset, so V and θ keep their values at onset, and the sphere
    # leaves once its shallowest point is below the back face: P = T + 2 Rs.
    plate = presets.plate("2024-T3/3.18")
    scenes = [pi.Scene(SPHERE, plate, 900.0, np.radians(t)) for t in (0.0, 30.0, 50.0)]
    simulation = brittle(docs_registry, 0.0)
    for scene in scenes:
        result = simulation.run(scene, record_trajectory=True)
        assert result.outcome == pi.Outcome.PERFORATION
        path = result.trajectory
        after = path.time >= result.failure_time
        assert after.sum() >= 2
        np.testing.assert_allclose(path.speed[after], result.exit_speed, rtol=1e-12)
        np.testing.assert_allclose(path.obliquity[after], result.exit_obliquity, atol=1e-12)
        exit_depth = plate.thickness + 2.0 * SPHERE.radius
        assert path.penetration[-1] == pytest.approx(exit_depth, rel=1e-9)
        assert result.exit_speed < 900.0  # the plate resisted until P*


def test_the_pages_integrator_is_fourth_order(docs_registry):
    """Classical RK4 at a fixed step against the closed form at normal incidence (as
    test_integrators does for dopri5 and segment): the error falls as h⁴."""
    plate = presets.plate("6061-T6/9.53")
    exact = closed_form_rest_depth(100.0)
    steps = np.array([0.08, 0.04, 0.02])
    errors = []
    for step in steps:
        simulation = pi.Simulation.from_names(
            failure="intact",
            integrator="rk4",
            integrator_settings={"step": step},
            registry=docs_registry,
        )
        result = simulation.run(pi.Scene(SPHERE, plate, 100.0, 0.0))
        errors.append(abs(result.max_penetration - exact) / exact)
    order = np.polyfit(np.log(steps), np.log(errors), 1)[0]
    assert 3.5 < order < 4.6, (order, errors)


def test_the_pages_integrator_fits_in_sixty_lines():
    page = (ROOT / "docs" / "plugins.md").read_text()
    integrator = next(b for b in re.findall(r"```python\n(.*?)```", page, re.S) if "rk4" in b)
    assert len(integrator.splitlines()) <= 60


@pytest.mark.parametrize("name", ["rk4"])
def test_the_pages_integrator_is_listed_with_its_settings(docs_registry, name):
    settings = docs_registry.get("integrator", name).setting_declarations()
    assert set(settings) == {"step", "max_steps"}


def test_the_pages_compiled_plug_in_runs_compiled_with_the_numpy_paths_results(docs_registry):
    """The page's kernel opts the isotropic law into the compiled path: a run takes it
    (compiled here in the foreground: "auto" would take the numpy path until the program
    is in the cache), and agrees with the numpy path within what the tolerance promises."""
    pytest.importorskip("numba")
    plate = presets.plate("2024-T3/3.18")
    scenes = pi.SceneBatch.grid(SPHERE, plate, np.linspace(100.0, 1400.0, 50), np.radians(
        np.linspace(0.0, 75.0, 40)
    ))  # fmt: skip
    runs = {
        engine: pi.Simulation.from_names(
            resistance="isotropic-poncelet", registry=docs_registry, engine=engine
        ).run_batch(scenes)
        for engine in ("compiled", "numpy")
    }
    assert runs["compiled"].stats["compiled_scenes"] == scenes.size == 2000
    assert runs["numpy"].stats["compiled_scenes"] == 0
    np.testing.assert_array_equal(runs["compiled"].outcome, runs["numpy"].outcome)
    speed = scenes.columns["impact_speed"]
    assert np.max(np.abs(runs["compiled"].exit_speed - runs["numpy"].exit_speed) / speed) <= 2e-7


def test_the_pages_pyproject_is_the_packages_complete():
    """The page shows the third-party package's pyproject.toml whole (its comments
    aside), and it declares the entry point the package is found by."""
    (toml,) = re.findall(r"```toml\n(.*?)```", (ROOT / "docs" / "plugins.md").read_text(), re.S)
    project = (ROOT / "tests" / "third_party" / "pyproject.toml").read_text()
    kept = [line for line in project.splitlines() if not line.startswith("#")]
    assert toml.splitlines() == kept
    assert '[project.entry-points.plateimpact]\nisotropic = "plateimpact_isotropic"' in toml
