"""Named edge cases of the model's numerics (issue 7): normal and near-normal incidence,
grazing incidence, the ballistic limit, P* on a branch of the contact geometry, and the
direction at rest, for every integrator."""

from __future__ import annotations

import attrs
import numpy as np
import pytest

import plateimpact as pi
from plateimpact import presets
from plateimpact.units import deg

SPHERE = presets.DEFAULT_SPHERE
INTEGRATORS = {
    "dopri5": {},
    # Grazing exits (angle and speed lost) agree with 3e-4's to 1.1e-3 of their values at
    # this step (the claims below hold to 5%), and θ = 0 against 1e-12 is exact at any step.
    "segment": {"step": 4e-3},
    "solve_ivp": {"rtol": 1e-10},
}


def simulation(integrator: str, **settings: float) -> pi.Simulation:
    return pi.Simulation.from_names(
        integrator=integrator, integrator_settings={**INTEGRATORS[integrator], **settings}
    )


@pytest.mark.parametrize("integrator", INTEGRATORS)
@pytest.mark.parametrize("plate", ["2024-T3/3.18", "6061-T6/9.53"])
def test_obliquity_zero_and_1e_12_give_the_same_impact(integrator, plate):
    """θ = 0 is the limit of θ → 0: nothing in the geometry divides by tan θ."""
    sim = simulation(integrator)
    exact, tiny = (sim.run(pi.Scene(SPHERE, presets.plate(plate), 600.0, t)) for t in (0, 1e-12))
    assert exact.outcome == tiny.outcome
    assert tiny.exit_speed == pytest.approx(exact.exit_speed, rel=1e-9, abs=1e-9)
    if exact.outcome == pi.Outcome.PERFORATION:
        assert exact.exit_obliquity == 0.0 and abs(tiny.exit_obliquity) < 1e-9


@pytest.mark.parametrize("integrator", INTEGRATORS)
def test_grazing_impacts_reflect_and_lose_speed_as_the_three_halves_power(integrator):
    """As ε = 90° − θ → 0 the sphere skims the surface: it leaves at 180° − θ, mirror-like,
    and loses a fraction of its speed ∝ ε^(3/2): the depth reached and so the force grow
    as ε (normal speed × a contact time that does not depend on it), and the force leans
    back against the path by φ ≈ α1/2 ≈ √(depth/2Rs) ∝ ε^(1/2) (eq 6)."""
    sim = simulation(integrator)
    plate = presets.plate("2024-T3/6.35")
    grazing = [89.9, 89.999]
    results = [sim.run(pi.Scene(SPHERE, plate, 800.0, t * deg)) for t in grazing]
    losses = []
    for theta, result in zip(grazing, results, strict=True):
        assert result.outcome == pi.Outcome.RICOCHET
        exit_from_surface = np.degrees(result.exit_obliquity) - 90.0
        assert exit_from_surface == pytest.approx(90.0 - theta, rel=0.05)
        losses.append(1.0 - result.exit_speed / 800.0)
    assert losses[0] / losses[1] == pytest.approx(100.0**1.5, rel=0.05)


def test_the_ballistic_limit_separates_embedment_from_perforation():
    """At normal incidence, bisected to 1e-9: just below the limit the sphere embeds, just
    above it perforates, leaving at the rest speed (1% of Vs: the documented rest rule,
    docs/model.md), and a little faster it leaves faster."""
    sim = pi.Simulation.from_names()
    plate = presets.plate("2024-T3/3.18")
    low, high = 300.0, 500.0
    while high - low > 1e-9 * high:
        mid = 0.5 * (low + high)
        perforates = sim.run(pi.Scene(SPHERE, plate, mid, 0.0)).outcome == pi.Outcome.PERFORATION
        low, high = (low, mid) if perforates else (mid, high)
    below, above, faster = (
        sim.run(pi.Scene(SPHERE, plate, v, 0.0)) for v in (low, high, 1.01 * high)
    )
    assert below.outcome == pi.Outcome.EMBEDMENT and below.exit_speed == 0.0
    assert above.outcome == pi.Outcome.PERFORATION
    assert above.exit_speed == pytest.approx(0.01 * high, rel=1e-3)
    assert faster.exit_speed > above.exit_speed


@pytest.mark.parametrize(
    ("pstar_over_radius", "obliquity_deg"),
    [(1.0, 0.0), (1.0, 30.0), (2.0, 0.0), (2.0, 30.0), (1.0 + np.sin(30 * deg), 30.0)],
)
def test_pstar_on_a_branch_of_the_contact_geometry_is_continuous(pstar_over_radius, obliquity_deg):
    """P* at P = Rs, 2Rs and Rs(1 + sin θ), where eqs 2–6 change branch: failing there,
    or a hair before or after, gives the same impact to the integrator's accuracy."""
    sim = pi.Simulation.from_names()
    plate = presets.plate("2024-T3/3.18")
    results = [
        sim.run(
            pi.Scene(
                SPHERE,
                attrs.evolve(plate, critical_penetration=pstar_over_radius * SPHERE.radius * f),
                700.0,
                obliquity_deg * deg,
            )
        )
        for f in (1 - 1e-9, 1.0, 1 + 1e-9)
    ]
    assert len({r.outcome for r in results}) == 1
    for r in results:
        assert np.isfinite(r.exit_speed) and np.isfinite(r.exit_obliquity)
        assert r.exit_speed == pytest.approx(results[1].exit_speed, abs=1e-6 * 700.0)
        assert r.exit_obliquity == pytest.approx(results[1].exit_obliquity, abs=1e-6)


def test_the_direction_at_rest_converges_for_every_integrator():
    """An embedment that still turns as V → 0 (the singularity of docs/model.md §4, "Rest"): with
    the rest rule its final direction is a property of the model, not of the step: the
    segment method converges to it at first order, and the adaptive methods agree."""
    scene = pi.Scene(SPHERE, presets.plate("6061-T6/9.53"), 800.0, 45 * deg)
    reference = simulation("solve_ivp", rtol=1e-12).run(scene)
    assert reference.outcome == pi.Outcome.EMBEDMENT
    assert 30 * deg < reference.exit_obliquity < 150 * deg  # still turning at rest
    adaptive = simulation("dopri5").run(scene).exit_obliquity
    assert abs(adaptive - reference.exit_obliquity) < 1e-4 * deg
    # A decade inside the first-order range: the error is 4.78° × step at 1e-2, 4.76° × step
    # at 1e-3 and at 4e-4.
    steps = [1e-2, 1e-3]
    errors = [
        abs(simulation("segment", step=s).run(scene).exit_obliquity - reference.exit_obliquity)
        for s in steps
    ]
    assert errors[1] < 0.2 * errors[0]  # first order: ~10x per decade of step
    assert errors[1] < 100 * deg * steps[1]  # 0.01 deg at 1e-4
