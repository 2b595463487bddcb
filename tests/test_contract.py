"""The plug-in contract: declared events, one Contact per call, the integrator's known
rates, and prepare on every plug-in (docs/plugins.md, "The contract")."""

from __future__ import annotations

import types
from typing import final

import attrs
import numpy as np
import pytest

import plateimpact as pi
from plateimpact import presets

SPHERE = presets.DEFAULT_SPHERE
PLATE = presets.plate("2024-T3/3.18")


def registry_with(*classes: type) -> pi.PluginRegistry:
    @pi.hookimpl
    def plateimpact_register(registry: pi.PluginRegistry) -> None:
        for cls in classes:
            registry.add(cls)

    return pi.load_registry(
        plugins=[types.SimpleNamespace(plateimpact_register=plateimpact_register)]
    )


def grid() -> pi.SceneBatch:
    return pi.SceneBatch.grid(SPHERE, PLATE, np.linspace(300.0, 1200.0, 7), np.radians([0, 40, 70]))


@final
@attrs.frozen
class NeverAsked(pi.FailureModel):
    """Declares no event: its step methods must never be called."""

    name = "never-asked"

    def onset_penetration(self, scenes: pi.SceneBatch) -> np.ndarray:
        return np.zeros(scenes.size) + 1e-9  # would fail at once, were onset an event

    def force_change(self, contact: pi.Contact) -> tuple[np.ndarray, np.ndarray]:
        raise AssertionError("force_change called without a declared onset")

    def perforation_margin(self, contact: pi.Contact) -> np.ndarray:
        raise AssertionError("perforation_margin called without a declared perforation")

    events = ()


def test_a_failure_model_without_events_is_never_asked_and_is_an_intact_plate():
    registry = registry_with(NeverAsked)
    batch = grid()
    never = pi.Simulation.from_names(failure="never-asked", registry=registry).run_batch(batch)
    # on the numpy path, where a model without kernels runs
    intact = pi.Simulation.from_names(failure="intact", registry=registry, engine="numpy")
    intact = intact.run_batch(batch)
    assert not never.plate_failed.any()
    for name, column in intact.columns.items():
        np.testing.assert_array_equal(never.columns[name], column, err_msg=name)


def test_a_failure_model_may_add_only_the_failure_events():
    cls = type("Foreign", (NeverAsked,), {"name": "foreign", "events": (pi.REST,)})
    with pytest.raises(pi.PluginError, match="declares event 'at rest'; a failure model adds"):
        pi.ImpactModel(pi.load_registry().create("resistance", "poncelet"), cls())


def test_the_event_table_is_the_one_source_of_rows_outcomes_and_restarts():
    assert len(pi.EVENT_NAMES) == len(pi.EVENTS)
    assert [pi.EVENTS[row] for row in (pi.ONSET, pi.PERFORATED)] == list(pi.FAILURE_EVENTS)
    assert pi.EVENT_OUTCOMES == {
        pi.CONTACT_LOST: pi.Outcome.RICOCHET,
        pi.PERFORATED: pi.Outcome.PERFORATION,
        pi.AT_REST: pi.Outcome.EMBEDMENT,
    }
    # Ties go to the earlier row: perforation over ricochet over embedment.
    assert pi.PERFORATED < pi.AT_REST and pi.CONTACT_LOST < pi.AT_REST


@final
@attrs.frozen
class Recording(pi.FailureModel):
    """Plugging-like relief at P*, recording what each method was given."""

    name = "recording"
    state_names = ("clock",)
    state_units = ("s",)
    seen: dict = attrs.field(factory=dict, eq=False)

    def onset_penetration(self, scenes: pi.SceneBatch) -> np.ndarray:
        return np.full(scenes.size, 1.5e-3)

    def _note(self, method: str, contact: pi.Contact) -> None:
        self.seen.setdefault(method, set()).add(contact.obliquity_rate is not None)
        assert isinstance(contact, pi.Contact) and contact.failure_state.shape[0] == 1
        assert (contact.obliquity >= 0.0).all()

    def force_change(self, contact: pi.Contact) -> tuple[np.ndarray, np.ndarray]:
        self._note("force_change", contact)
        drag, lift = contact.law.contact_force(
            contact.penetration, contact.obliquity, contact.speed
        )
        return -0.5 * drag, -0.5 * lift

    def perforation_margin(self, contact: pi.Contact) -> np.ndarray:
        self._note("perforation_margin", contact)
        return contact.penetration - contact.scenes.thickness - 2 * contact.scenes.radius

    def initial_state(self, contact: pi.Contact) -> np.ndarray:
        self._note("initial_state", contact)
        np.testing.assert_array_equal(contact.failure_state, 0.0)  # zero before onset
        return np.zeros((1, contact.penetration.size))

    def state_rates(self, contact: pi.Contact) -> np.ndarray:
        self._note("state_rates", contact)
        return np.ones_like(contact.failure_state)  # d(clock)/dt = 1


def test_each_step_method_gets_one_contact_with_the_rate_only_where_it_is_asked_for():
    model = Recording()
    registry = registry_with(Recording)
    simulation = pi.Simulation(
        pi.ImpactModel(registry.create("resistance", "poncelet"), model),
        registry.create("integrator", "dopri5"),
    )
    result = simulation.run_batch(grid(), record_trajectory=True)
    assert result.plate_failed.any()
    assert model.seen == {
        "force_change": {False},
        "perforation_margin": {False},
        "initial_state": {False},
        "state_rates": {True},
    }
    # The state integrates d(clock)/dt = 1 from onset: it is the time since failure.
    for i in np.flatnonzero(result.plate_failed):
        path = result.trajectory_of(i)
        after = path.time >= result.failure_time[i]
        clock = path.failure_state["clock"][after]
        np.testing.assert_allclose(clock, path.time[after] - result.failure_time[i], atol=1e-15)


def test_the_driver_reuses_the_known_rates_and_nothing_else_changes(monkeypatch):
    # dopri5 carries f(y) (first same as last); without known_rates the driver evaluates
    # it again for the branch prediction: the same steps, one more evaluation per step.
    simulation = pi.Simulation.from_names(failure="hinge", engine="numpy")  # its driver
    batch = grid()
    reused = simulation.run_batch(batch)
    cls = type(simulation.integrator)
    monkeypatch.setattr(cls, "known_rates", lambda self, state: None)
    again = simulation.run_batch(batch)
    for name, column in reused.columns.items():
        np.testing.assert_array_equal(again.columns[name], column, err_msg=name)
    extra = again.stats["force_evaluations"] - reused.stats["force_evaluations"]
    assert extra == reused.stats["accepted_steps"] + reused.stats["rejected_steps"]


def test_prepare_belongs_to_every_plug_in():
    assert pi.Plugin.prepare is pi.ResistanceLaw.prepare is pi.FailureModel.prepare
    assert pi.Integrator.prepare is pi.Plugin.prepare


def test_the_built_in_laws_formula_is_one_function_of_numbers_or_arrays():
    # What a compiled path compiles is the function the numpy path calls: per scene on
    # numbers it gives, bit for bit, what the law gives on the arrays.
    from plateimpact_plugins.poncelet import poncelet_stress

    rng = np.random.default_rng(3)
    speed, incidence = rng.uniform(0, 2000, 50), rng.uniform(-1.5, 1.5, 50)
    scenes = pi.SceneBatch.of({"a": rng.uniform(1e8, 1e9, 50), "b": rng.uniform(1e2, 1e4, 50)}, 50)
    law = pi.load_registry().create("resistance", "poncelet")
    on_arrays = law.stress(speed, incidence, scenes)
    one_by_one = [
        poncelet_stress(float(v), float(psi), float(a), float(b))
        for v, psi, a, b in zip(speed, incidence, scenes.a, scenes.b, strict=True)
    ]
    np.testing.assert_array_equal(on_arrays, one_by_one)
