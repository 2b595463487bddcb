"""What plugging, hinge and variable-P* failure share: separation along a fixed plane."""

from __future__ import annotations

from abc import abstractmethod
from typing import ClassVar

import numpy as np

from plateimpact import Column, Contact, FailureModel, Parameter, SceneBatch, geometry

from .report.constants import FAILURE_ANGLE
from .report.plane import failure_plane_depth


class PlaneSeparation(FailureModel):
    """Abstract: at onset the plate separates along the ring at α* on the sphere.

    The ring's depth at onset, h = Rs cos α* + P* − Rs (eq 8 with P = P*, the onset
    penetration), defines a plane fixed in the plate (α* is measured "with respect to the
    plate orientation"). Material deeper than h no longer resists: the relieved force F′
    is the resistance law on the part of the contact surface below that plane (eqs 9–14,
    i.e. eqs 2–6 with P − h for P), subtracted from the intact force F* as a vector
    (eq 15; drag and lift each with its own inclination). When h < 0 the ring is still
    above the front surface at onset and the whole contact region separates: h = 0.

    Perforation is complete when the front layer 0 < z < h no longer touches the forward
    hemisphere: P − h >= Rs (1 + sin θ) while θ < 90°.

    Subclasses say when failure starts (:meth:`onset_penetration`) and may add to the
    force (:meth:`force_change` of the hinge adds the finger).
    """

    plate_constants: ClassVar[tuple[Parameter, ...]] = (FAILURE_ANGLE,)
    columns: ClassVar[tuple[Column, ...]] = (
        Column("failure_plane_depth", "m", "depth h of the failure plane (eq 8)"),
    )

    @abstractmethod
    def onset_penetration(self, scenes: SceneBatch) -> np.ndarray: ...

    def prepare(self, scenes: SceneBatch) -> dict[str, np.ndarray]:
        onset = self.onset_penetration(scenes)
        depth = failure_plane_depth(scenes.radius, scenes.failure_angle, onset)  # eq 8
        return {"failure_plane_depth": depth}

    def relief(self, contact: Contact) -> tuple[np.ndarray, np.ndarray]:
        """−F′ as (drag, lift) [N]: the force no longer exerted beyond the plane (eq 15)."""
        below_plane = contact.penetration - contact.scenes.failure_plane_depth
        relieved_drag, relieved_lift = contact.law.contact_force(
            below_plane, contact.obliquity, contact.speed
        )
        return -relieved_drag, -relieved_lift

    def force_change(self, contact: Contact) -> tuple[np.ndarray, np.ndarray]:
        return self.relief(contact)

    def branch_margins(self, contact: Contact) -> np.ndarray:
        # The relieved force is eqs 2–6 below the failure plane: the same branch surfaces
        # with P − h for P [m].
        scenes = contact.scenes
        below_plane = contact.penetration - scenes.failure_plane_depth
        return geometry.branch_margins(below_plane, contact.obliquity, scenes.radius)

    def perforation_margin(self, contact: Contact) -> np.ndarray:
        # Depth of the forward hemisphere's shallowest point below the failure plane.
        scenes = contact.scenes
        reach = scenes.radius * (1.0 + np.sin(np.minimum(contact.obliquity, 0.5 * np.pi)))
        return contact.penetration - scenes.failure_plane_depth - reach
