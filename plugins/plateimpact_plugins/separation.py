"""What plugging, hinge and variable-P* failure share: separation along a fixed plane."""

from __future__ import annotations

from abc import abstractmethod
from typing import Any, ClassVar

import numpy as np

from plateimpact import (
    Column,
    Contact,
    FailureKernels,
    FailureModel,
    KernelContact,
    Parameter,
    SceneBatch,
    elementary,
    geometry,
    kernels,
)

from .report.constants import FAILURE_ANGLE
from .report.plane import failure_plane_depth


def plane_perforation_margin(
    penetration: Any, obliquity: Any, radius: Any, plane_depth: Any
) -> Any:
    """Depth [m] of the forward hemisphere's shallowest point below the failure plane at
    ``plane_depth`` h [m]: P − h − Rs(1 + sin min(θ, π/2)), >= 0 once the front layer no
    longer touches it (perforation); P [m], θ [rad], Rs [m], numbers or arrays. (sin from
    :mod:`plateimpact.elementary`: the compiled path evaluates it for 64 scenes at once.)"""
    reach = radius * (1.0 + elementary.sin(np.minimum(obliquity, 0.5 * np.pi)))
    return penetration - plane_depth - reach


def plane_branch_surfaces(
    penetration: Any, obliquity: Any, radius: Any, plane_depth: Any
) -> tuple[Any, Any]:
    """The branch surfaces of the relieved force [m]: eqs 2–6 below the failure plane at
    ``plane_depth`` h [m], i.e. with P − h for P (:func:`plateimpact.geometry.branch_surfaces`)."""
    return geometry.branch_surfaces(penetration - plane_depth, obliquity, radius)


def separation_perforation_margin(contact: KernelContact) -> float:
    """:meth:`PlaneSeparation.perforation_margin` of one scene [m]."""
    return plane_perforation_margin(
        contact.penetration, contact.obliquity, contact.radius, contact.constants[0]
    )


def separation_branch_margins(contact: KernelContact, out: Any) -> None:
    """:meth:`PlaneSeparation.branch_margins` of one scene, into ``out[0:2]`` [m]."""
    out[0], out[1] = plane_branch_surfaces(
        contact.penetration, contact.obliquity, contact.radius, contact.constants[0]
    )


#: The functions of numbers a compiled path compiles (besides the core's geometry).
KERNELS = (
    failure_plane_depth,
    plane_perforation_margin,
    plane_branch_surfaces,
    separation_perforation_margin,
    separation_branch_margins,
)


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
    kernel_columns: ClassVar[tuple[str, ...]] = ("failure_plane_depth",)
    kernels: ClassVar[FailureKernels | None] = FailureKernels(
        kernels.no_force_change,  # the relief is all (relief_column)
        separation_perforation_margin,
        branch_rows=2,
        branch_margins=separation_branch_margins,
        relief_column=0,  # failure_plane_depth
    )

    @abstractmethod
    def onset_penetration(self, scenes: SceneBatch) -> np.ndarray: ...

    def prepare(self, scenes: SceneBatch) -> dict[str, np.ndarray]:
        onset = self.onset_penetration(scenes)
        depth = failure_plane_depth(scenes.radius, scenes.failure_angle, onset)  # eq 8
        return {"failure_plane_depth": depth}

    def relief(self, contact: Contact) -> tuple[np.ndarray, np.ndarray]:
        """−F′ as (drag, lift) [N]: the force no longer exerted beyond the plane (eq 15)."""
        # F′: the law on the contact surface below the plane, eqs 2–6 with P − h for P
        # (compiled: FailureKernels.relief_column, the same formulas)
        depth = contact.scenes.failure_plane_depth
        relieved_drag, relieved_lift = contact.law.contact_force(
            contact.penetration - depth, contact.obliquity, contact.speed
        )
        return -relieved_drag, -relieved_lift  # eq 15

    def force_change(self, contact: Contact) -> tuple[np.ndarray, np.ndarray]:
        return self.relief(contact)

    def branch_margins(self, contact: Contact) -> np.ndarray:
        scenes = contact.scenes
        return np.stack(
            plane_branch_surfaces(
                contact.penetration, contact.obliquity, scenes.radius, scenes.failure_plane_depth
            )
        )

    def perforation_margin(self, contact: Contact) -> np.ndarray:
        scenes = contact.scenes
        return plane_perforation_margin(
            contact.penetration, contact.obliquity, scenes.radius, scenes.failure_plane_depth
        )
