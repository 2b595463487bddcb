"""Crater sections (eqs 31–39): shape invariants and agreement with the report's curve."""

from __future__ import annotations

import functools

import numpy as np
import pytest

import plateimpact as pi
from plateimpact import presets
from plateimpact.model.crater import crater_section
from plateimpact.units import deg

RS = presets.DEFAULT_SPHERE.radius
#: A section is a function of the trajectory alone, whatever integrator made it: the
#: default's (samples ~0.02 Rs apart, most circles kept), and the report's segments at
#: their default step (samples <= 1e-3 Rs apart, thinned to one circle per Rs/400).
SIMULATIONS = {
    "default": pi.Simulation.from_names(),
    "segment": pi.Simulation.from_names(integrator="segment", integrator_settings={"step": 1e-3}),
}


@functools.cache
def crater(plate, speed, obliquity_deg, integrator="default"):
    scene = pi.Scene(presets.DEFAULT_SPHERE, presets.plate(plate), speed, obliquity_deg * deg)
    result = SIMULATIONS[integrator].run(scene, record_trajectory=True)
    return result, crater_section(result.trajectory, RS)


CASES = [
    ("6061-T6/9.53", 300.0, 0.0, "default"),  # embedment, normal incidence
    ("6061-T6/9.53", 263.0, 60.0, "default"),  # ricochet (Figure 35's speed)
    ("6061-T6/9.53", 263.0, 60.0, "segment"),  # the same, thinned
    ("6061-T6/9.53", 737.0, 60.0, "default"),
    ("2024-T3/6.35", 700.0, 45.0, "default"),  # embedment
    ("2024-T3/3.18", 900.0, 45.0, "default"),  # perforation
    ("2024-T3/1.27", 200.0, 45.0, "default"),  # ricochet after failure
]


@pytest.mark.parametrize(("plate", "speed", "obliquity", "integrator"), CASES)
def test_crater_starts_at_origin_stays_below_surface_and_is_as_deep_as_the_sphere_went(
    plate, speed, obliquity, integrator
):
    result, section = crater(plate, speed, obliquity, integrator)
    assert section.lateral[0] == 0.0 and section.depth[0] == 0.0
    assert section.depth[-1] == 0.0 and np.all(np.diff(section.lateral) >= 0.0)
    assert np.all(section.depth >= 0.0)
    assert section.max_depth == pytest.approx(result.max_penetration, rel=1e-12)


def test_normal_incidence_crater_is_symmetric_about_the_impact_point():
    result, section = crater("6061-T6/9.53", 300.0, 0.0)
    assert result.outcome is pi.Outcome.EMBEDMENT
    offsets = np.linspace(0.0, 0.5 * section.length, 200)
    left = np.interp(section.impact_point - offsets, section.lateral, section.depth)
    right = np.interp(section.impact_point + offsets, section.lateral, section.depth)
    np.testing.assert_allclose(left, right, atol=1e-3 * RS)
    # The pit is as wide as the circle the sphere cut at its deepest: 2 Re.
    p = result.max_penetration
    assert section.length == pytest.approx(2.0 * np.sqrt(2 * RS * p - p * p), rel=1e-5)


def test_floor_follows_the_reports_curve_where_it_is_the_envelope():
    # Eqs 31–32: the lower edge of the swept sphere, x = X + Rs sin θ, y = Y − Rs cos θ.
    # On the report's dense segments, thinned to the circles kept for the section.
    result, section = crater("6061-T6/9.53", 263.0, 60.0, "segment")
    t = result.trajectory
    x = (t.penetration - RS) + RS * np.sin(t.obliquity)
    y = t.lateral - RS * np.cos(t.obliquity)
    below = x > 0.05 * RS
    floor = np.interp(y[below] + section.impact_point, section.lateral, section.depth)
    np.testing.assert_allclose(floor, x[below], atol=2e-3 * RS)
