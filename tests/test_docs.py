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


def test_the_pages_resistance_law_is_the_third_party_packages_code():
    page = (ROOT / "docs" / "plugins.md").read_text()
    law = re.findall(r"```python\n(.*?)```", page, re.S)[0]
    package = (ROOT / "tests" / "third_party" / "plateimpact_isotropic" / "__init__.py").read_text()
    assert law in package


def test_the_pages_usage_example_ran_with_the_rate_constant(docs_plugins):
    # The example's plate has c = 0.3: a strength term that grows with speed stops the
    # sphere sooner than eq 1 alone (c = 0) on the same plate.
    result = docs_plugins["result"]
    plain = pi.Simulation.from_names().run(
        pi.Scene(SPHERE, presets.plate("6061-T6/9.53"), 700.0, np.radians(30.0))
    )
    assert result.outcome == plain.outcome
    assert result.max_penetration < 0.95 * plain.max_penetration


def test_the_pages_failure_model_fails_where_it_says(docs_registry):
    plate = presets.plate("2024-T3/3.18")
    batch = pi.SceneBatch.grid(SPHERE, plate, [500.0, 900.0, 1300.0], np.radians([0.0, 30.0]))
    plugging = pi.Simulation.from_names(registry=docs_registry).run_batch(batch)
    same = pi.Simulation.from_names(failure="speed-plugging", registry=docs_registry)
    for name, column in same.run_batch(batch).columns.items():  # growth 0: plugging
        np.testing.assert_array_equal(column, plugging.columns[name], err_msg=name)
    grown = pi.Simulation.from_names(
        failure="speed-plugging", failure_settings={"growth": 0.1}, registry=docs_registry
    ).run_batch(batch)
    failed = grown.plate_failed
    assert failed.any()
    onset = plate.critical_penetration * (1 + 0.1 * batch.impact_speed / 1e3)
    np.testing.assert_allclose(grown.failure_penetration[failed], onset[failed], rtol=1e-9)


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
