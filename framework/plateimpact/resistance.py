"""The ResistanceLaw interface: the stress the plate exerts on the presented area."""

from __future__ import annotations

from abc import ABC, abstractmethod
from typing import ClassVar

import numpy as np

from .batch import SceneBatch
from .geometry import contact_geometry


class ResistanceLaw(ABC):
    """How hard the plate pushes back, per unit of presented area.

    The core computes the contact geometry (presented area A and the force's inclination
    φ, eqs 2–6); a resistance law supplies the stress σ so that the force is F = A σ,
    directed along the contact-plane normal, at ψ = θ − φ from the sphere's path.

    To write one: subclass, set ``name`` (the name users select it by), implement
    :meth:`stress` on arrays, and register the class from a ``plateimpact_register``
    hook (see :mod:`plateimpact.hookspecs`). Settings, if any, are constructor
    arguments (an attrs class is the easy way). ``stress`` runs inside the step loop:
    numpy only, no Python loop over scenes, no hook calls.
    """

    name: ClassVar[str]
    version: ClassVar[str] = "1"

    def prepare(self, batch: SceneBatch) -> dict[str, np.ndarray]:
        """Per-scene columns to compute once per batch, before any step (default none)."""
        return {}

    @abstractmethod
    def stress(self, speed: np.ndarray, incidence: np.ndarray, batch: SceneBatch) -> np.ndarray:
        """Stress on the presented area [N/m²].

        Parameters
        ----------
        speed : V [m/s], one per scene of ``batch``.
        incidence : ψ [rad], the angle between the path and the force's line.
        batch : the scenes, for their plate constants (``batch.a``, ``batch.b``, ...).
        """

    def settings(self) -> dict[str, object]:
        """The plug-in's settings, for archives (default: none)."""
        return {}


def contact_force(
    law: ResistanceLaw,
    penetration: np.ndarray,
    obliquity: np.ndarray,
    speed: np.ndarray,
    batch: SceneBatch,
) -> tuple[np.ndarray, np.ndarray]:
    """Drag and lift [N] of ``law`` on the contact surface (eqs 1, 22–24).

    ``penetration`` is measured from the plane bounding the resisting material: the front
    surface for the intact force F*, the failure plane (P − h) for the relieved force F′
    of eqs 9–14. Drag opposes the motion; positive lift turns θ upward (toward ricochet).
    """
    area, inclination = contact_geometry(penetration, obliquity, batch.radius)
    incidence = obliquity - inclination  # ψ, eq 22
    force = area * law.stress(speed, incidence, batch)  # eq 1
    return force * np.cos(incidence), force * np.sin(incidence)  # eqs 23, 24
