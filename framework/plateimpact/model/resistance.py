"""The ResistanceLaw interface: the stress the plate exerts on the presented area."""

from __future__ import annotations

from abc import ABC, abstractmethod
from collections.abc import Callable
from typing import Any, ClassVar

import numpy as np

from .batch import SceneBatch
from .geometry import contact_surface
from .plugin import Plugin


class ResistanceLaw(Plugin, ABC):
    """How hard the plate pushes back, per unit of presented area.

    The core computes the contact geometry (presented area A and the force's inclination
    φ, eqs 2–6); a resistance law supplies the stress σ so that the force is F = A σ,
    directed along the contact-plane normal, at ψ = θ − φ from the sphere's path.

    To write one: subclass, set ``name``, declare the plate constants it reads in
    ``plate_constants``, implement :meth:`stress` on arrays, and register the class from
    a ``plateimpact_register`` hook (:func:`plateimpact.hookimpl`). Settings are attrs
    fields. ``stress`` runs inside the step loop: numpy only, no Python loop over
    scenes, no hook calls.

    To run on the compiled path too, set ``stress_kernel`` to the same formula for
    numbers, ``stress(speed [m/s], incidence [rad], constants) -> σ [N/m²]``, reading the
    columns named in ``kernel_columns`` from ``constants`` (:mod:`plateimpact.model.kernels`).
    """

    #: The compiled path's stress (None: this law runs on the numpy path only).
    stress_kernel: ClassVar[Callable[..., Any] | None] = None

    @abstractmethod
    def stress(self, speed: np.ndarray, incidence: np.ndarray, scenes: SceneBatch) -> np.ndarray:
        """Stress on the presented area [N/m²]: a function of its arguments and the law's
        settings alone.

        Parameters
        ----------
        speed : V [m/s], one per scene of ``scenes``.
        incidence : ψ [rad], the angle between the path and the force's line.
        scenes : this law's view of the scenes: the core columns, the plate constants it
            declared (``scenes.a``) and the columns it prepared.
        """


def force_on_contact(
    penetration: Any,
    obliquity: Any,
    speed: Any,
    radius: Any,
    surface: Callable[..., tuple[Any, ...]],
    stress: Callable[..., Any],
    stress_argument: Any,
) -> tuple[Any, Any]:
    """Drag and lift [N] on the contact surface (eqs 1, 22–24) at ``penetration`` P [m],
    ``obliquity`` θ [rad] and ``speed`` V [m/s] of a sphere of ``radius`` Rs [m]: the
    formula once, for arrays and numbers alike.

    ``surface(P, θ, Rs)`` gives the presented area A [m²], the force inclination φ [rad]
    and cos ψ, sin ψ of the incidence (:func:`~plateimpact.model.geometry.contact_surface`
    on arrays, its ``_kernel`` on numbers) and ``stress(V, ψ, stress_argument)`` the
    stress σ [N/m²] (a law's ``stress`` with its view of the scenes, or a compiled stress
    kernel with a scene's constants: one argument, not a tuple to unpack, so that
    compiled code can inline this).
    """
    return force_on_surface(
        surface(penetration, obliquity, radius), obliquity, speed, stress, stress_argument
    )


def force_on_surface(
    surface: tuple[Any, ...],
    obliquity: Any,
    speed: Any,
    stress: Callable[..., Any],
    stress_argument: Any,
) -> tuple[Any, Any]:
    """``force_on_contact`` from the contact ``surface`` already evaluated at
    ``obliquity`` θ [rad] (the geometry's A [m²], φ [rad], cos ψ, sin ψ, ...), at
    ``speed`` V [m/s]: drag and lift [N] (eqs 1, 22–24)."""
    stress_value = stress(speed, obliquity - surface[1], stress_argument)  # eqs 1, 22
    return force_from_stress(surface, stress_value)


def force_from_stress(surface: tuple[Any, ...], stress_value: Any) -> tuple[Any, Any]:
    """Drag and lift [N] of the stress σ [N/m²] on the contact ``surface`` (A [m²], φ,
    cos ψ, sin ψ, ...): F = A σ along the contact-plane normal (eqs 1, 23, 24)."""
    force = surface[0] * stress_value
    return force * surface[2], force * surface[3]


def contact_force(
    law: ResistanceLaw,
    penetration: np.ndarray,
    obliquity: np.ndarray,
    speed: np.ndarray,
    batch: SceneBatch,
) -> tuple[np.ndarray, np.ndarray]:
    """Drag and lift [N] of ``law`` on the contact surface (eqs 1, 22–24) at
    ``penetration`` P [m], ``obliquity`` θ [rad] and ``speed`` V [m/s], one per scene
    (``force_on_contact`` on arrays).

    ``penetration`` is measured from the plane bounding the resisting material: the front
    surface for the intact force F*, the failure plane (P − h) for the relieved force F′
    of eqs 9–14. Drag opposes the motion; positive lift turns θ upward (toward ricochet).
    ``batch`` is the law's view of the scenes.
    """
    return force_on_contact(
        penetration, obliquity, speed, batch.radius, contact_surface, law.stress, batch
    )


class BoundResistance:
    """The model's resistance law on its own view of a set of scenes: what a failure
    model is given to compute forces on parts of the contact surface (the relieved force
    F′ beyond a failure plane, a hinged finger) without seeing the law's columns.

    ``index``: the scenes of ``batch`` it is about (None: all); the subset of the law's
    view is taken when the law is first used, so a failure method that never asks for a
    force (a margin) costs no copy of the law's columns.
    """

    __slots__ = ("_batch", "_index", "law")

    def __init__(
        self, law: ResistanceLaw, batch: SceneBatch, index: np.ndarray | None = None
    ) -> None:
        self.law = law
        self._batch = batch
        self._index = index

    @property
    def batch(self) -> SceneBatch:
        """The law's view of the scenes it is about."""
        if self._index is not None:
            self._batch, self._index = self._batch.take(self._index), None
        return self._batch

    def stress(self, speed: np.ndarray, incidence: np.ndarray) -> np.ndarray:
        """σ [N/m²] at speed V [m/s] and incidence ψ [rad]."""
        return self.law.stress(speed, incidence, self.batch)

    def contact_force(
        self, penetration: np.ndarray, obliquity: np.ndarray, speed: np.ndarray
    ) -> tuple[np.ndarray, np.ndarray]:
        """Drag and lift [N] on the contact surface below a plane ``penetration`` [m] above
        the sphere's deepest point, at ``obliquity`` θ [rad] and ``speed`` V [m/s]
        (:func:`contact_force`)."""
        return contact_force(self.law, penetration, obliquity, speed, self.batch)


#: The functions of numbers a compiled path compiles.
KERNELS = (force_from_stress, force_on_surface, force_on_contact)
