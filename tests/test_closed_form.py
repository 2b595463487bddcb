"""Normal incidence on an intact plate against the energy integral's closed form.

With θ ≡ 0 the force is A(a + bV²) on A = π Re² (P <= Rs) or π Rs² (beyond), so
m V dV/dP = −A (a + b V²) integrates to  a + b V² = (a + b Vs²) exp(−2 b G(P)/m)  with
G(P) = ∫₀ᴾ A dp = π(Rs P² − P³/3) for P <= Rs and 2π Rs³/3 + π Rs² (P − Rs) beyond.
"""

from __future__ import annotations

import numpy as np
import pytest
from conftest import COARSE_STEPS, EVERY_INTEGRATOR
from scipy.optimize import brentq

import plateimpact as pi
from plateimpact import presets

PLATE = presets.plate("6061-T6/9.53")
SPEED = 300.0  # [m/s], embeds (the 9.53-mm plate is perforated above ~700 m/s)
FINEST_STEP = 1e-4  # the segment integrator's finest documented step


def _g(p, rs):
    return np.where(
        p <= rs,
        np.pi * (rs * p**2 - p**3 / 3.0),
        2.0 * np.pi * rs**3 / 3.0 + np.pi * rs**2 * (p - rs),
    )


def closed_form_max_penetration(sphere, plate, speed, rest_fraction):
    """P where V falls to the rest speed, from the energy integral."""
    a, b, m = plate.a, plate.b, sphere.mass
    rest = rest_fraction * speed
    target = m / (2.0 * b) * np.log((a + b * speed**2) / (a + b * rest**2))
    return brentq(lambda p: _g(p, sphere.radius) - target, 0.0, 20 * sphere.radius, xtol=1e-15)


def run_normal(sphere, step, *, record=False):
    simulation = pi.Simulation.from_names(
        failure="intact", integrator="segment", integrator_settings={"step": step}
    )
    return simulation.run(pi.Scene(sphere, PLATE, SPEED, 0.0), record_trajectory=record)


def test_max_penetration_matches_closed_form_at_finest_step(sphere):
    result = run_normal(sphere, FINEST_STEP, record=True)
    assert result.outcome is pi.Outcome.EMBEDMENT
    exact = closed_form_max_penetration(sphere, PLATE, SPEED, 0.01)
    assert result.max_penetration == pytest.approx(exact, rel=1e-4)
    # The whole speed history follows the closed form, not just its end point.
    t = result.trajectory
    predicted = (PLATE.a + PLATE.b * SPEED**2) * np.exp(
        -2.0 * PLATE.b * _g(t.penetration, sphere.radius) / sphere.mass
    )
    np.testing.assert_allclose(PLATE.a + PLATE.b * t.speed**2, predicted, rtol=1e-3)


def test_error_shrinks_at_first_order(sphere):
    exact = closed_form_max_penetration(sphere, PLATE, SPEED, 0.01)
    steps = np.array([8e-3, 4e-3, 2e-3, 1e-3])
    errors = np.array([abs(run_normal(sphere, s).max_penetration - exact) for s in steps])
    order = np.polyfit(np.log(steps), np.log(errors), 1)[0]
    assert 0.85 < order < 1.15, (order, errors)


@pytest.mark.parametrize("integrator", EVERY_INTEGRATOR)
def test_normal_incidence_stays_on_the_normal(sphere, integrator, docs_registry):
    # θ = 0 exactly: no lift, so no lateral motion at all, through failure and perforation.
    # Exact zeros at any step: the fixed-step integrators at 10 and 5 times their defaults.
    coarse = COARSE_STEPS.get(integrator, {})
    simulation = pi.Simulation.from_names(
        integrator=integrator, registry=docs_registry, integrator_settings=coarse
    )
    for speed in (300.0, 1200.0):
        result = simulation.run(pi.Scene(sphere, PLATE, speed, 0.0), record_trajectory=True)
        assert np.all(result.trajectory.lateral == 0.0)
        assert np.all(result.trajectory.obliquity == 0.0)
    assert result.outcome is pi.Outcome.PERFORATION and result.exit_obliquity == 0.0
