"""Property-based tests over the physical domain (issue 7): every integrator and failure
model on random spheres, plates and impacts. Profiles: "ci" (default) and "stress"
(HYPOTHESIS_PROFILE=stress), registered in conftest.py."""

from __future__ import annotations

import math

import numpy as np
import pytest
from hypothesis import assume, given
from hypothesis import strategies as st

import plateimpact as pi
from plateimpact.units import deg, mm

INTEGRATORS = ["dopri5", "segment", "solve_ivp"]
FAILURES = ["plugging", "hinge", "intact", "variable-pstar"]


def log_uniform(low: float, high: float) -> st.SearchStrategy[float]:
    return st.floats(math.log(low), math.log(high)).map(math.exp)


@st.composite
def scenes(draw: st.DrawFn, obliquity: st.SearchStrategy[float] | None = None) -> pi.Scene:
    """A scene anywhere in the domain of issue 7: radius 0.5–20 mm, density 1–20 g/cm³,
    speed 1 m/s–5 km/s, obliquity 0–89.9°, a and b over three decades around Table 1's,
    P* from 0.1 to 10 Rs, thickness 0.1–10 Rs, α* 10–80°."""
    radius = draw(log_uniform(0.5 * mm, 20 * mm))
    sphere = pi.Sphere.of_density(radius, draw(log_uniform(1000.0, 20000.0)))
    plate = pi.Plate(
        "random",
        thickness=draw(log_uniform(0.1, 10.0)) * radius,
        a=draw(log_uniform(3e7, 3e10)),
        b=draw(log_uniform(30.0, 3e4)),
        critical_penetration=draw(log_uniform(0.1, 10.0)) * radius,
        failure_angle=draw(st.floats(10.0, 80.0)) * deg,
    )
    speed = draw(log_uniform(1.0, 5000.0))
    theta = draw(obliquity if obliquity is not None else st.floats(0.0, 89.9)) * deg
    return pi.Scene(sphere, plate, speed, theta)


def simulation(integrator: str, failure: str) -> pi.Simulation:
    # The properties hold at any step: the segment method runs at 5e-2 Rs/Vs here (its
    # accuracy at the default step is test_closed_form's and the benchmarks' business).
    settings = {"step": 5e-2} if integrator == "segment" else {}
    return pi.Simulation.from_names(
        failure=failure, integrator=integrator, integrator_settings=settings
    )


@pytest.mark.parametrize("integrator", INTEGRATORS)
@pytest.mark.parametrize("failure", FAILURES)
@given(scene=scenes())
def test_every_scene_ends_in_an_outcome_with_finite_physical_outputs(integrator, failure, scene):
    result = simulation(integrator, failure).run(scene, record_trajectory=True)
    values = [result.exit_speed, result.exit_obliquity, result.contact_time]
    assert result.outcome in tuple(pi.Outcome)
    assert all(math.isfinite(v) for v in values) and math.isfinite(result.max_penetration)
    assert 0.0 <= result.exit_speed <= scene.impact_speed
    if result.outcome == pi.Outcome.RICOCHET:
        assert 0.5 * math.pi < result.exit_obliquity <= math.pi
    elif result.outcome == pi.Outcome.PERFORATION:
        assert 0.0 <= result.exit_obliquity < 0.5 * math.pi
    path = result.trajectory
    for column in (path.time, path.penetration, path.lateral, path.obliquity, path.speed):
        assert np.all(np.isfinite(column))
    # Drag never pushes: the speed does not rise along the path (beyond the integrator's
    # interpolation rounding, 1e-9 of the impact speed).
    assert np.all(np.diff(path.speed) <= 1e-9 * scene.impact_speed)
    assert np.all(np.diff(path.time) >= 0.0)


@pytest.mark.parametrize("integrator", INTEGRATORS)
@pytest.mark.parametrize("failure", FAILURES)
@given(scene=scenes(obliquity=st.just(0.0)))
def test_normal_incidence_never_moves_sideways(integrator, failure, scene):
    result = simulation(integrator, failure).run(scene, record_trajectory=True)
    assert np.all(result.trajectory.lateral == 0.0)
    assert np.all(result.trajectory.obliquity == 0.0) or result.exit_obliquity == math.pi
    assert result.outcome != pi.Outcome.RICOCHET or result.exit_obliquity == math.pi


@pytest.mark.parametrize("failure", FAILURES)
@given(scene=scenes())
def test_results_are_continuous_in_impact_speed_within_an_outcome(failure, scene):
    """A relative change of 1e-7 in impact speed moves the exit by at most 1% of the
    impact speed and 1° when neither the outcome nor the failure changes (near a ballistic
    limit the exit speed rises like a square root, so 1% bounds even that)."""
    sim = simulation("dopri5", failure)
    nudged = pi.Scene(
        scene.sphere, scene.plate, scene.impact_speed * (1 + 1e-7), scene.impact_obliquity
    )
    a, b = sim.run(scene), sim.run(nudged)
    assume(a.outcome == b.outcome and a.plate_failed == b.plate_failed)
    assert abs(b.exit_speed - a.exit_speed) <= 1e-2 * scene.impact_speed
    if a.outcome != pi.Outcome.EMBEDMENT:
        assert abs(b.exit_obliquity - a.exit_obliquity) <= 1.0 * deg


@pytest.mark.parametrize("failure", FAILURES)
@given(scene=scenes())
def test_tightening_the_tolerance_moves_results_within_the_expected_error(failure, scene):
    """dopri5 at rtol 1e-8 against 1e-11: within 1e4 × rtol of the impact speed and
    0.5e4 × rtol rad, the largest ratio of error to rtol in the work-precision benchmark
    (benchmarks/work_precision.py: 1.0e-5 Vs and 5.6e-4° at rtol 1e-8) with room."""
    coarse, fine = (
        pi.Simulation.from_names(failure=failure, integrator_settings={"rtol": rtol}).run(scene)
        for rtol in (1e-8, 1e-11)
    )
    assume(coarse.outcome == fine.outcome)  # not a scene on an outcome boundary
    assert abs(coarse.exit_speed - fine.exit_speed) <= 1e-4 * scene.impact_speed
    if fine.outcome != pi.Outcome.EMBEDMENT:
        assert abs(coarse.exit_obliquity - fine.exit_obliquity) <= 5e-5
