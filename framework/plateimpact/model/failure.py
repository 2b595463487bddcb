"""The FailureModel interface: when the plate fails and what failure changes."""

from __future__ import annotations

from abc import ABC, abstractmethod
from typing import ClassVar, NamedTuple

import numpy as np

from .batch import SceneBatch
from .events import FAILURE_EVENTS, Event
from .kernels import FailureKernels
from .plugin import Plugin
from .resistance import BoundResistance


class Contact(NamedTuple):
    """What a failure model is asked about: the motion of some scenes at one instant, their
    constants, and the resistance law. Arrays have one entry per scene.

    ``penetration`` P [m]; ``obliquity`` θ [rad], always >= 0 (a failure model sees the
    mirror image of a path that has swung across the plate normal); ``speed`` V [m/s];
    ``failure_state`` the model's state variables, shape ``(len(state_names), n)``
    (zero before onset, and always ``(0, n)`` for a stateless model); ``scenes`` the
    model's view of the scenes (core columns, its plate constants, its prepared
    columns: ``scenes.radius``, ``scenes.critical_penetration``); ``law`` the model's
    resistance law on its own view of the same scenes; ``obliquity_rate`` dθ/dt [rad/s],
    known only where the rates of the failure state are asked for (None elsewhere: it
    follows from the force being computed).
    """

    penetration: np.ndarray
    obliquity: np.ndarray
    speed: np.ndarray
    failure_state: np.ndarray
    scenes: SceneBatch
    law: BoundResistance
    obliquity_rate: np.ndarray | None = None


class FailureModel(Plugin, ABC):
    """When the plate fails, and how the force on the sphere changes once it has.

    Every method is a function of its arguments and the model's settings (its attrs
    fields) alone, on arrays over scenes: once per batch, ``onset_penetration(scenes)``
    (and ``prepare(scenes)``, :class:`~plateimpact.model.plugin.Plugin`); at every step,
    for the scenes whose plate has failed, the methods taking one :class:`Contact`:

    * :meth:`onset_penetration`: the penetration at which failure starts (P* in the
      report; ``inf`` for a plate that never fails). Failure starts when P first reaches
      it and lasts for the rest of the impact.
    * :meth:`force_change`: what failure adds to the intact force F* (the plugging relief
      is −F′, eq 15).
    * :meth:`perforation_margin`: >= 0 once the sphere has passed the material that still
      resists, which ends the impact in perforation.
    * optionally :meth:`branch_margins` (where the force switches formula),
      :meth:`initial_state` and :meth:`state_rates` (failure that evolves).

    **Events.** ``events`` declares which of the failure events
    (:data:`~plateimpact.model.events.FAILURE_EVENTS`: onset, perforation) the model adds
    to the impact; the driver computes no margin for the others. A plate that never fails
    declares none.

    **Failure state.** A model whose failure evolves (the hinge's finger angle β) names
    its variables in ``state_names`` and their units in ``state_units``; the integrator
    carries them per scene, zero until onset, where :meth:`initial_state` sets them, and
    advances them with :meth:`state_rates`.

    Subclass, set ``name``, declare the plate constants it reads (``plate_constants``) and
    the columns it prepares (``columns``), implement the three abstract methods in numpy
    (no Python loop over scenes, no hook calls), and register the class from a
    ``plateimpact_register`` hook.
    """

    #: The failure events this model adds (default: onset and perforation).
    events: ClassVar[tuple[Event, ...]] = FAILURE_EVENTS
    #: Names of the variables this model integrates after failure (default: none).
    state_names: ClassVar[tuple[str, ...]] = ()
    #: Their units, for archives (e.g. ``("rad",)``).
    state_units: ClassVar[tuple[str, ...]] = ()
    #: The same methods for numbers, for the compiled path (None: this model runs on
    #: the numpy path only; :mod:`plateimpact.model.kernels`).
    kernels: ClassVar[FailureKernels | None] = None

    @abstractmethod
    def onset_penetration(self, scenes: SceneBatch) -> np.ndarray:
        """Penetration at which the plate fails [m], per scene; ``inf`` for never."""

    @abstractmethod
    def force_change(self, contact: Contact) -> tuple[np.ndarray, np.ndarray]:
        """Drag and lift [N] that failure adds to the intact force (negative: relief);
        ``contact.law.contact_force(P − h, θ, V)`` is the force on the part of the contact
        surface beyond a plane at depth h (eqs 9–14)."""

    @abstractmethod
    def perforation_margin(self, contact: Contact) -> np.ndarray:
        """A length [m] that crosses zero upward when perforation is complete."""

    def branch_margins(self, contact: Contact) -> np.ndarray:
        """Margins that cross zero where :meth:`force_change` or :meth:`state_rates`
        switches formula, shape (rows, n), any unit per row (default: none).

        The force stays continuous there but not smooth, and an error-controlled step
        that straddles such a surface is both costly and less accurate than its error
        estimate claims; the adaptive integrator steps onto it instead (docs/
        integrators.md, "branch surfaces"). A row is only ever compared in sign with
        itself, so rows may mix units.
        """
        return np.empty((0, contact.penetration.size))

    def initial_state(self, contact: Contact) -> np.ndarray:
        """Failure state at onset, shape ``(len(state_names), n)`` (default: zeros)."""
        return np.zeros((len(self.state_names), contact.penetration.size))

    def state_rates(self, contact: Contact) -> np.ndarray:
        """Time derivatives of the failure state [unit/s], same shape as
        ``contact.failure_state``; ``contact.obliquity_rate`` is dθ/dt [rad/s] from the net
        force, failure included (default: constant state)."""
        return np.zeros_like(contact.failure_state)
