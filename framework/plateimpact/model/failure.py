"""The FailureModel interface: when the plate fails and what failure changes."""

from __future__ import annotations

from abc import ABC, abstractmethod
from typing import ClassVar

import numpy as np

from .batch import SceneBatch
from .plugin import Plugin
from .resistance import BoundResistance


class FailureModel(Plugin, ABC):
    """When the plate fails, and how the force on the sphere changes once it has.

    The core calls the methods below with arrays over the scenes of a batch:

    * :meth:`onset_penetration` once per batch: the penetration at which failure starts
      (P* in the report; ``inf`` for a plate that never fails). Failure is an event: it
      starts when P first reaches this value and lasts for the rest of the impact.
    * :meth:`force_change` at every step, **only for scenes whose plate has failed**:
      what failure adds to the intact force F* (the plugging relief is −F′, eq 15).
    * :meth:`perforation_margin`, likewise only for failed scenes: >= 0 once the sphere
      has passed the material that still resists, which ends the impact in perforation.

    Subclass, set ``name``, declare the plate constants it reads (``plate_constants``) and
    the columns it prepares (``columns``), implement the three methods in numpy, and
    register the class from a ``plateimpact_register`` hook. Per-scene constants that do
    not change during the impact belong in :meth:`prepare`, which runs once per batch.
    ``batch`` arguments are this model's view of the scenes (core columns, its plate
    constants, its prepared columns); ``law`` is the model's resistance law on its own
    view (:class:`~plateimpact.model.resistance.BoundResistance`).

    **Failure state.** A model whose failure evolves (the hinge's finger angle β) names
    its variables in ``state_names``; the integrator then carries them per scene as an
    array of shape ``(len(state_names), n)``, sets them with :meth:`initial_state` at
    onset and advances them with :meth:`state_rates`. ``state`` arguments are that array,
    restricted to the failed scenes; stateless models get shape ``(0, n)`` and ignore it.

    **Arguments**, arrays with one entry per scene: ``penetration`` P [m], ``obliquity``
    θ [rad] (always >= 0: the model sees the mirror image of a path that has swung
    across the normal), ``speed`` V [m/s], ``obliquity_rate`` dθ/dt [rad/s].
    """

    #: Names of the variables this model integrates after failure (default: none).
    state_names: ClassVar[tuple[str, ...]] = ()
    #: Their units, for archives (e.g. ``("rad",)``).
    state_units: ClassVar[tuple[str, ...]] = ()

    def prepare(self, batch: SceneBatch) -> dict[str, np.ndarray]:
        """The per-scene columns declared in ``columns``, computed once per batch (default
        none)."""
        return {}

    @abstractmethod
    def onset_penetration(self, batch: SceneBatch) -> np.ndarray:
        """Penetration at which the plate fails [m], per scene; ``inf`` for never."""

    @abstractmethod
    def force_change(
        self,
        penetration: np.ndarray,
        obliquity: np.ndarray,
        speed: np.ndarray,
        state: np.ndarray,
        batch: SceneBatch,
        law: BoundResistance,
    ) -> tuple[np.ndarray, np.ndarray]:
        """Drag and lift [N] that failure adds to the intact force (negative: relief);
        ``law.contact_force(P − h, θ, V)`` is the force on the part of the contact surface
        beyond a plane at depth h (eqs 9–14)."""

    @abstractmethod
    def perforation_margin(
        self, penetration: np.ndarray, obliquity: np.ndarray, batch: SceneBatch
    ) -> np.ndarray:
        """A length [m] that crosses zero upward when perforation is complete."""

    def branch_margins(
        self,
        penetration: np.ndarray,
        obliquity: np.ndarray,
        state: np.ndarray,
        batch: SceneBatch,
    ) -> np.ndarray:
        """Margins that cross zero where :meth:`force_change` or :meth:`state_rates`
        switches formula, shape (rows, n), any unit per row (default: none).

        The force stays continuous there but not smooth, and an error-controlled step
        that straddles such a surface is both costly and less accurate than its error
        estimate claims; the adaptive integrator steps onto it instead (docs/
        integrators.md, "branch surfaces"). Called only for failed scenes; a row is only
        ever compared in sign with itself, so rows may mix units.
        """
        return np.empty((0, np.shape(penetration)[0]))

    def initial_state(
        self,
        penetration: np.ndarray,
        obliquity: np.ndarray,
        speed: np.ndarray,
        batch: SceneBatch,
    ) -> np.ndarray:
        """Failure state at onset, shape ``(len(state_names), n)`` (default: empty)."""
        return np.zeros((len(self.state_names), penetration.size))

    def state_rates(
        self,
        penetration: np.ndarray,
        obliquity: np.ndarray,
        speed: np.ndarray,
        obliquity_rate: np.ndarray,
        state: np.ndarray,
        batch: SceneBatch,
    ) -> np.ndarray:
        """Time derivatives of the failure state [unit/s], same shape as ``state``.

        ``obliquity_rate`` is dθ/dt [rad/s] from the net force, failure included.
        """
        return np.zeros_like(state)
