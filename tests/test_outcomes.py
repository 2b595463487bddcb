"""Outcomes and their invariants: the behaviour the report describes (docs/model.md §8)."""

from __future__ import annotations

import re

import numpy as np
import pytest
from conftest import COARSE_STEPS, EVERY_INTEGRATOR, sweep

import plateimpact as pi
from plateimpact import presets
from plateimpact_plugins import Plugging, Poncelet

LETTER = {1: "R", 2: "E", 3: "P"}


def letters(result):
    return "".join(LETTER[int(o)] for o in result.outcome)


@pytest.mark.parametrize("plate", ["2024-T3/6.35", "6061-T6/9.53"])
@pytest.mark.parametrize("obliquity", [45.0, 60.0])
def test_thick_plates_ricochet_then_embed_then_perforate(plate, obliquity):
    result = sweep(plate, np.linspace(50.0, 1500.0, 30), obliquity)
    assert re.fullmatch("R+E+P+", letters(result)), letters(result)


def test_thick_plate_ricochet_obliquity_rises_to_180_and_stays():
    # Report, thick-plate ricochet: exit obliquity rises monotonically from just above
    # 90° to 180° and then remains constant.
    result = sweep("6061-T6/9.53", np.linspace(50.0, 700.0, 27), 45.0)
    ricochet = result.exit_obliquity[result.outcome == pi.Outcome.RICOCHET]
    assert np.all(np.diff(ricochet) >= 0.0)
    assert 0.5 * np.pi < ricochet[0] < np.radians(120.0)
    # 180° is reached (held there by the integrator, or approached as ψ → 0 in the
    # symmetric turn-around contact) and kept by every faster ricochet.
    assert ricochet[-1] >= np.pi - 1e-6 and np.all(ricochet <= np.pi)


@pytest.mark.parametrize("integrator", EVERY_INTEGRATOR)
def test_obliquity_is_held_at_180_once_within_the_tolerance(sphere, integrator, docs_registry):
    """θ = π is a stable equilibrium approached exponentially (docs/model.md, "θ = π"):
    the hold starts once π − θ <= TURN_BACK_TOLERANCE, so a sphere that turns back deep
    in a thick plate reaches exactly 180° in finite time and keeps it to rest."""
    scene = pi.Scene(sphere, presets.plate("2024-T3/6.35"), 689.0, np.radians(50.1))
    # The fixed-step integrators at 10 and 5 times their default steps: the hold starts
    # on the located event, so where it starts does not depend on the step (π − θ there
    # is the same to 16 digits at segment steps 1e-3 to 5e-2 and rk4 steps 1e-2 to 0.1).
    coarse = COARSE_STEPS.get(integrator, {})
    simulation = pi.Simulation.from_names(
        integrator=integrator, registry=docs_registry, integrator_settings=coarse
    )
    result = simulation.run(scene, record_trajectory=True)
    assert result.outcome == pi.Outcome.EMBEDMENT and result.exit_obliquity == np.pi
    obliquity = result.trajectory.obliquity
    held = np.flatnonzero(obliquity == np.pi)
    assert held.size and np.all(obliquity[held[0] :] == np.pi)  # held from then on
    before = obliquity[: held[0]]
    # The hold starts where π − θ reaches the tolerance (the event, located to rounding),
    # not where θ would reach π.
    tolerance = pi.ImpactModel.TURN_BACK_TOLERANCE
    assert np.pi - before[-1] == pytest.approx(tolerance, rel=1e-6)
    assert np.all(np.pi - before[:-1] > tolerance)
    assert np.all(np.diff(before[before > 0.9 * np.pi]) >= 0.0)  # a monotone approach


def test_thin_plate_ricochets_after_failure_just_below_embedment():
    # Report, thin-plate ricochet: failure during ricochet gives a narrow band of
    # ricochets at lower exit speed and higher exit obliquity just below the embedment
    # range -- a spike in exit obliquity and a precipitous drop in exit speed.
    speeds = np.arange(150.0, 262.0, 1.0)  # the embedment range is 206.25–208.75 m/s
    result = sweep("2024-T3/1.27", speeds, 45.0)
    ricochet = result.outcome == pi.Outcome.RICOCHET
    band = ricochet & result.plate_failed
    intact = ricochet & ~result.plate_failed
    assert band.sum() >= 2
    # Order along the speed axis: intact ricochets, the band, then no more ricochets.
    kinds = "".join(
        "b" if f else "i" if r else c for f, r, c in zip(band, intact, letters(result), strict=True)
    )
    assert re.fullmatch("i+b+E+P+", kinds), kinds
    band_speed, band_obliquity = result.exit_speed[band], result.exit_obliquity[band]
    # Exit speed falls all the way; exit obliquity climbs (to 180°, where it is held).
    assert np.all(np.diff(band_speed) < 0.0) and np.all(np.diff(band_obliquity) >= 0.0)
    assert band_speed[-1] < 0.5 * result.exit_speed[intact].max()
    assert band_obliquity.min() > result.exit_obliquity[intact].max()


def test_invariants_on_random_scenes():
    rng = np.random.default_rng(20261121)
    names = list(presets.PLATES)
    scenes = [
        pi.Scene(
            presets.DEFAULT_SPHERE,
            presets.plate(names[rng.integers(len(names))]),
            rng.uniform(30.0, 1500.0),
            np.radians(rng.uniform(0.0, 75.0)),
        )
        for _ in range(40)
    ]
    result = pi.Simulation.from_names().run_batch(scenes, record_trajectory=True)
    speed = np.array([s.impact_speed for s in scenes])
    pstar = np.array([s.plate.critical_penetration for s in scenes])
    outcome, exit_obliquity = result.outcome, result.exit_obliquity
    assert set(np.unique(outcome)) <= {1, 2, 3}
    for name in ("exit_speed", "exit_obliquity", "contact_time", "max_penetration"):
        assert np.all(np.isfinite(result.columns[name])), name
    assert np.all(result.exit_speed <= speed)
    ricochet, perforation = outcome == pi.Outcome.RICOCHET, outcome == pi.Outcome.PERFORATION
    assert np.all((exit_obliquity[ricochet] > 0.5 * np.pi) & (exit_obliquity[ricochet] <= np.pi))
    assert np.all(exit_obliquity[perforation] < 0.5 * np.pi)
    assert np.all(result.exit_speed[outcome == pi.Outcome.EMBEDMENT] == 0.0)
    # Failure happens at P*, and only if P reaches it.
    assert np.all(result.plate_failed == (result.max_penetration >= pstar * (1 - 1e-9)))
    np.testing.assert_allclose(
        result.failure_penetration[result.plate_failed], pstar[result.plate_failed], rtol=1e-4
    )
    # A resisting plate never speeds the sphere up (dense output: to rounding).
    for i in range(len(scenes)):
        assert np.all(np.diff(result.trajectory_of(i).speed) <= 1e-9 * speed[i]), i


def test_failed_plate_never_pushes_the_sphere_forward(sphere):
    # Whatever plane h the plate separates along, F* − F′ keeps a non-negative drag:
    # the relieved region is part of the contact region.
    model = pi.ImpactModel(Poncelet(), Plugging())
    rng = np.random.default_rng(7)
    n = 200_000
    rs = sphere.radius
    batch = pi.SceneBatch(
        {
            "radius": np.full(n, rs),
            "mass": np.full(n, sphere.mass),
            "thickness": np.full(n, 3e-3),
            "a": 10 ** rng.uniform(8, 10, n),
            "b": 10 ** rng.uniform(2, 4, n),
            "critical_penetration": rng.uniform(0.05, 2.5, n) * rs,
            "failure_angle": rng.uniform(0.05, 1.5, n),
            "impact_speed": np.full(n, 500.0),
            "impact_obliquity": np.zeros(n),
        }
    )
    bound = model.bind(batch)
    pen = rng.uniform(0.0, 4.0, n) * rs
    obl = rng.uniform(0.0, np.pi, n)
    speed = rng.uniform(0.0, 2000.0, n)
    state = model.new_failure_state(n)
    drag, _ = model.forces(pen, obl, speed, np.ones(n, bool), state, bound)
    assert drag.min() >= 0.0


@pytest.mark.parametrize("failure", ["plugging", "hinge"])
def test_a_path_across_the_normal_is_the_mirror_image(sphere, failure):
    # θ < 0 (a step that overshoots the normal) is the same contact seen in a mirror:
    # equal drag, opposite lift; the failure model only ever sees |θ|.
    model = pi.Simulation.from_names(failure=failure).model
    n = 400
    batch = pi.SceneBatch.from_scenes(
        [pi.Scene(sphere, presets.plate("2024-T3/3.18"), 600.0, 0.3)] * n
    )
    bound = model.bind(batch)
    rng = np.random.default_rng(7)
    pen = rng.uniform(0.0, 2.5, n) * sphere.radius
    obl = rng.uniform(1e-6, np.pi, n)
    speed = rng.uniform(10.0, 1500.0, n)
    failed = rng.random(n) < 0.5
    state = model.new_failure_state(n)
    model.start_failure(failed, pen, obl, speed, state, bound)
    drag, lift = model.forces(pen, obl, speed, failed, state, bound)
    mirror_drag, mirror_lift = model.forces(pen, -obl, speed, failed, state, bound)
    np.testing.assert_array_equal(mirror_drag, drag)
    np.testing.assert_array_equal(mirror_lift, -lift)
    held = np.zeros(n, bool)
    y = np.vstack([pen, np.zeros(n), obl, speed, state])
    mirrored = y.copy()
    mirrored[pi.OBLIQUITY] *= -1.0
    rates, mirror_rates = (
        model.rates(y, failed, held, bound),
        model.rates(mirrored, failed, held, bound),
    )
    np.testing.assert_array_equal(mirror_rates[pi.OBLIQUITY], -rates[pi.OBLIQUITY])
    np.testing.assert_array_equal(mirror_rates[pi.LATERAL], -rates[pi.LATERAL])
    for row in (pi.PENETRATION, pi.SPEED, *range(pi.KINEMATIC_STATE, y.shape[0])):
        np.testing.assert_array_equal(mirror_rates[row], rates[row])


def test_a_process_pool_gives_the_serial_results_bit_for_bit(sphere):
    from concurrent.futures import ProcessPoolExecutor

    rng = np.random.default_rng(3)
    scenes = [
        pi.Scene(sphere, presets.plate(name), speed, np.radians(ob))
        for name, speed, ob in zip(
            rng.choice(list(presets.PLATES), 40),
            rng.uniform(80.0, 1500.0, 40),
            rng.uniform(0.0, 70.0, 40),
            strict=True,
        )
    ]
    simulation = pi.Simulation.from_names()
    serial = simulation.run_batch(scenes, record_trajectory=True)
    with ProcessPoolExecutor(2) as pool:
        spread = simulation.run_batch(scenes, record_trajectory=True, executor=pool, chunk_size=7)
    for name, column in serial.columns.items():
        np.testing.assert_array_equal(spread.columns[name], column, err_msg=name)
    for name, column in serial.trajectory.values.items():
        np.testing.assert_array_equal(spread.trajectory[name], column, err_msg=name)
    with pytest.raises(pi.ParameterError, match="chunk_size"):
        with ProcessPoolExecutor(1) as pool:
            simulation.run_batch(scenes, executor=pool, chunk_size=0)


@pytest.mark.parametrize(
    ("integrator", "settings"),
    [("segment", {"step": 1e-2}), ("dopri5", {})],
    ids=["segment", "dopri5"],
)
def test_scene_result_does_not_depend_on_its_batch(sphere, integrator, settings):
    # Bit for bit at any step: the segment method at ten times its default step.
    target = pi.Scene(sphere, presets.plate("2024-T3/3.18"), 640.0, np.radians(60.0))
    others = [
        pi.Scene(sphere, presets.plate(name), speed, np.radians(ob))
        for name, speed, ob in [
            ("SAE1010/1.47", 90.0, 0.0),
            ("6061-T6/9.53", 1400.0, 20.0),
            ("2024-T3/1.27", 200.0, 45.0),
        ]
    ]
    simulation = pi.Simulation.from_names(integrator=integrator, integrator_settings=settings)
    alone = simulation.run_batch([target])
    mixed = simulation.run_batch([others[0], target, *others[1:]])
    for name, column in alone.columns.items():
        np.testing.assert_array_equal(column[0], mixed.columns[name][1], err_msg=name)


class TestRestRule:
    """An embedding sphere's final direction is its direction when V = f·Vs (docs/model.md)."""

    # Comes to rest shallow (P < Rs(1 + sin θ)) with ψ ≠ 0, so lift turns it as V → 0.
    SCENE_ARGS = ("6061-T6/9.53", 474.0, 9.5)

    def run(self, sphere, step=None, fraction=1e-2, record=False):
        """The scene on the segment method at ``step``, or (None) on the default integrator."""
        plate, speed, obliquity = self.SCENE_ARGS
        simulation = pi.Simulation.from_names(
            integrator=None if step is None else "segment",
            integrator_settings=None if step is None else {"step": step},
            rest_speed_fraction=fraction,
        )
        scene = pi.Scene(sphere, presets.plate(plate), speed, np.radians(obliquity))
        return simulation.run(scene, record_trajectory=record)

    def test_the_last_step_lands_on_the_rest_speed(self, sphere):
        result = self.run(sphere, 2e-3, record=True)
        assert result.outcome is pi.Outcome.EMBEDMENT
        assert result.trajectory.speed[-1] == pytest.approx(0.01 * 474.0, rel=1e-9)
        assert result.exit_obliquity == result.trajectory.obliquity[-1]

    def test_final_direction_converges_with_the_step(self, sphere):
        directions = [self.run(sphere, s).exit_obliquity for s in (4e-3, 2e-3, 1e-3, 5e-4)]
        changes = np.abs(np.diff(directions))
        # First order: each halving of the step halves the change.
        np.testing.assert_allclose(changes[1:] / changes[:-1], 0.5, atol=0.1)
        assert changes[-1] < np.radians(0.15)

    def test_final_direction_is_set_by_the_rest_fraction(self, sphere):
        # The continuous model keeps turning as V → 0 (dθ/d ln V = −tan ψ), so the rule,
        # not the step, must fix it: a lower rest speed turns the sphere further (the
        # model's claim: on the default integrator).
        coarse = self.run(sphere, fraction=1e-1).exit_obliquity
        fine = self.run(sphere, fraction=1e-2).exit_obliquity
        assert np.degrees(fine - coarse) > 3.0
