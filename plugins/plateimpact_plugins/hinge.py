"""Hinge ("finger") failure of oblique impacts on steel (report eqs 7, 16–21)."""

from __future__ import annotations

from typing import Any, final

import attrs
import numpy as np

from plateimpact import (
    Column,
    Contact,
    FailureKernels,
    KernelContact,
    Parameter,
    Range,
    SceneBatch,
    kernels,
)

from .report.constants import CRITICAL_PENETRATION, FAILURE_ANGLE
from .separation import (
    PlaneSeparation,
    separation_branch_margins,
    separation_perforation_margin,
)

HALF_PI = 0.5 * np.pi

FINGER_AREA_SCALE = Parameter(
    "finger_area_scale",
    "multiplies the finger's presented area As (0: no finger, i.e. plugging)",
    range=Range(0.0, 10.0),  # a sensitivity factor: 10x the finger is no longer a hinge
    default=1.0,
)
HINGE_OBLIQUITY = Parameter(
    "hinge_obliquity",
    "theta1, the obliquity where the finger's force switches from eq 19 to eq 20 "
    "(none: 90 deg - alpha* of each plate)",
    "rad",
    Range(0.0, HALF_PI, True, True),
    "deg",
    np.pi / 180,
    default=None,
    optional=True,
)


def finger_half_angle(finger_angle: Any) -> Any:
    """β/2 [rad] of the finger angle β [rad], 0 once the finger has peeled off."""
    return 0.5 * np.maximum(finger_angle, 0.0)


def finger_area(half_angle: Any, radius: Any, area_scale: Any) -> Any:
    """As = π [Rs sin(β/2)]² [m²] (eq 17), times ``area_scale``; β/2 [rad], Rs [m]."""
    return area_scale * np.pi * (radius * np.sin(half_angle)) ** 2


def rising_finger_incidence(obliquity: Any, opening: Any, half_angle: Any) -> Any:
    """ψ″ = 90° + θ − θ1 − β/2 [rad] (eq 19, θ < θ1), with ``opening`` 90° − θ1 [rad]."""
    return obliquity + (opening - half_angle)


def rolling_finger_incidence(half_angle: Any) -> Any:
    """ψ″ = 90° − β/2 [rad] (eq 20, θ >= θ1)."""
    return HALF_PI - half_angle


def finger_kernel(
    obliquity: float,
    finger_angle: float,
    radius: float,
    theta1: float,
    opening: float,
    area_scale: float,
) -> tuple[float, float]:
    """:meth:`Hinge.finger` of numbers, (As [m²], ψ″ [rad]), for a compiled path."""
    half_angle = finger_half_angle(finger_angle)
    area = finger_area(half_angle, radius, area_scale)
    if obliquity < theta1:
        return area, rising_finger_incidence(obliquity, opening, half_angle)
    return area, rolling_finger_incidence(half_angle)


def initial_finger_angle(obliquity: Any, failure_angle: Any, theta1: Any) -> Any:
    """β at onset [rad]: 2α* − max(θ − θ1, 0), from θ, α* and θ1 [rad]."""
    return 2.0 * failure_angle - np.maximum(obliquity - theta1, 0.0)


def finger_is_held(obliquity: Any, finger_angle: Any, failure_angle: Any, theta1: Any) -> Any:
    """True while β [rad] neither shrinks nor acts as shrinking: held at 2α* while θ <=
    θ1, or peeled off (β <= 0); θ, α*, θ1 [rad]."""
    held = (obliquity <= theta1) & (finger_angle >= 2.0 * failure_angle)
    return held | (finger_angle <= 0.0)


def peeling_rate(obliquity_rate: Any, speed: Any, radius: Any) -> Any:
    """−dβ/dt [rad/s] of a shrinking finger: dθ/dt + V/Rs (eq 18 per unit time), never
    negative (a finger does not re-attach); dθ/dt [rad/s], V [m/s], Rs [m]."""
    return np.maximum(obliquity_rate + speed / radius, 0.0)


def finger_rate_kernel(
    obliquity: float,
    finger_angle: float,
    obliquity_rate: float,
    speed: float,
    radius: float,
    failure_angle: float,
    theta1: float,
) -> float:
    """dβ/dt [rad/s] of numbers (:meth:`Hinge.state_rates`), for a compiled path."""
    if finger_is_held(obliquity, finger_angle, failure_angle, theta1):
        return 0.0
    return -peeling_rate(obliquity_rate, speed, radius)


# The hinge's kernel constants: h, θ1, 90° − θ1, α* [m, rad, rad, rad], finger_area_scale.
_DEPTH, _THETA1, _OPENING, _ALPHA, _SCALE = range(5)


def finger_force(contact: KernelContact) -> tuple[float, float]:
    """The finger's drag and lift [N] (eqs 16-21): :meth:`Hinge.force_change` of one
    scene besides the relief (``relief_column``)."""
    c = contact.constants
    area, incidence = finger_kernel(
        contact.obliquity, contact.failure_state[0], contact.radius, c[_THETA1], c[_OPENING],
        c[_SCALE],
    )  # fmt: skip
    force = area * kernels.law_stress(contact.speed, incidence, contact)  # eq 16
    return force * np.cos(incidence), force * np.sin(incidence)


def hinge_branch_margins(contact: KernelContact, out: Any) -> None:
    """:meth:`Hinge.branch_margins` of one scene, into ``out[0:4]``."""
    separation_branch_margins(contact, out)
    out[2] = contact.obliquity - contact.constants[_THETA1]
    out[3] = contact.failure_state[0]


def hinge_initial_state(contact: KernelContact, out: Any) -> None:
    """:meth:`Hinge.initial_state` of one scene: β at onset [rad]."""
    c = contact.constants
    out[0] = initial_finger_angle(contact.obliquity, c[_ALPHA], c[_THETA1])


def hinge_state_rates(contact: KernelContact, out: Any) -> None:
    """:meth:`Hinge.state_rates` of one scene: dβ/dt [rad/s]."""
    c = contact.constants
    out[0] = finger_rate_kernel(
        contact.obliquity, contact.failure_state[0], contact.obliquity_rate, contact.speed,
        contact.radius, c[_ALPHA], c[_THETA1],
    )  # fmt: skip


#: The functions of numbers a compiled path compiles (callees before callers).
KERNELS = (
    finger_half_angle,
    finger_area,
    rising_finger_incidence,
    rolling_finger_incidence,
    finger_kernel,
    initial_finger_angle,
    finger_is_held,
    peeling_rate,
    finger_rate_kernel,
    finger_force,
    hinge_branch_margins,
    hinge_initial_state,
    hinge_state_rates,
)


@final
@attrs.frozen
class Hinge(PlaneSeparation):
    """Plugging relief plus the resistance of a finger of plate hinged ahead of the sphere.

    At onset the plate separates as in plugging (eqs 8–15), but on oblique impacts on
    steel the separated material stays attached at a hinge and keeps pushing on the
    sphere over a cap of angular width β (the finger angle, Figure 9 of the report):

        F″ = As σ(V, ψ″),   As = π [Rs sin(β/2)]²          (eqs 16–17)

    with σ the resistance law (eq 1 for Poncelet). The net force is F* − F′ + F″ (eq 21),
    each part's drag and lift with its own angle. The finger angle:

    * starts at 2α* − max(θ − θ1, 0) at onset (the report: α* + 90° − θ if that is less
      than 2α*, else 2α*), and is held at 2α* while θ <= θ1;
    * then shrinks as the sphere rolls along the finger: dβ = −dθ − dS/Rs (eqs 7, 18),
      never growing back (a finger that has peeled off does not re-attach);
    * stops acting when it reaches 0 (As = 0 from then on).

    F″ acts at ψ″ = 90° + θ − θ1 − β/2 from the path while θ < θ1 and 90° − β/2 after
    (eqs 19–20), on the same side as F*: its drag resists the motion and its lift turns
    the sphere outward. θ1 = 90° − α* (docs/hinge.md, "Readings we took", 1, gives the
    reasons).

    Parameters
    ----------
    finger_area_scale : float
        Multiplies As, >= 0 (default 1). 0 removes the finger: the model is then plugging,
        bit for bit.
    hinge_obliquity : float or None
        θ1 [rad], in (0, π/2); None for 90° − α* of each plate.
    """

    name = "hinge"
    state_names = ("finger_angle",)
    state_units = ("rad",)
    plate_constants = (CRITICAL_PENETRATION, FAILURE_ANGLE)
    columns = (
        *PlaneSeparation.columns,
        Column("theta1", "rad", "theta1 of eqs 19-20: where the finger's force switches"),
        Column("hinge_opening", "rad", "90 deg - theta1"),
    )

    kernels = FailureKernels(
        finger_force,
        separation_perforation_margin,
        branch_rows=4,
        branch_margins=hinge_branch_margins,
        initial_state=hinge_initial_state,
        state_rates=hinge_state_rates,
        relief_column=_DEPTH,
    )

    finger_area_scale: float = FINGER_AREA_SCALE.field()
    hinge_obliquity: float | None = HINGE_OBLIQUITY.field()

    def kernel_constants(self, scenes: SceneBatch) -> np.ndarray:
        scale = np.full(scenes.size, self.finger_area_scale)
        columns = (scenes.failure_plane_depth, scenes.theta1, scenes.hinge_opening)
        return np.stack([*columns, scenes.failure_angle, scale])

    def onset_penetration(self, scenes: SceneBatch) -> np.ndarray:
        return scenes.critical_penetration

    def prepare(self, scenes: SceneBatch) -> dict[str, np.ndarray]:
        if self.hinge_obliquity is None:
            theta1 = HALF_PI - scenes.failure_angle
            # 90° − θ1 kept as α* itself, not recomputed: with β = 2α* the finger force
            # then lies exactly along the normal at θ = 0 (no lift from rounding).
            opening = scenes.failure_angle
        else:
            theta1 = np.full(scenes.size, self.hinge_obliquity)
            opening = HALF_PI - theta1
        return {**super().prepare(scenes), "theta1": theta1, "hinge_opening": opening}

    def initial_state(self, contact: Contact) -> np.ndarray:
        scenes = contact.scenes
        onset = initial_finger_angle(contact.obliquity, scenes.failure_angle, scenes.theta1)
        return onset[np.newaxis]

    def state_rates(self, contact: Contact) -> np.ndarray:
        scenes, obliquity = contact.scenes, contact.obliquity
        assert contact.obliquity_rate is not None  # given wherever rates are asked for
        finger_angle = contact.failure_state[0]
        held = finger_is_held(obliquity, finger_angle, scenes.failure_angle, scenes.theta1)
        peeling = peeling_rate(contact.obliquity_rate, contact.speed, scenes.radius)
        return np.where(held, 0.0, -peeling)[np.newaxis]

    def branch_margins(self, contact: Contact) -> np.ndarray:
        # Besides the relief's: θ − θ1 [rad], where ψ″ switches from eq 19 to eq 20 and β
        # starts to shrink, and β [rad], which stops the finger at 0.
        theta1 = contact.scenes.theta1
        finger_rows = np.stack([contact.obliquity - theta1, contact.failure_state[0]])
        return np.concatenate([super().branch_margins(contact), finger_rows])

    def finger(
        self, obliquity: np.ndarray, finger_angle: np.ndarray, scenes: SceneBatch
    ) -> tuple[np.ndarray, np.ndarray]:
        """The finger's presented area As [m²] (eq 17) and the angle ψ″ [rad] of its force
        from the path (eqs 19–20), at obliquity θ [rad] and finger angle β [rad]. The
        finger touches the sphere over the cap of angular width β centred on that force
        line, i.e. from θ − ψ″ − β/2 to θ − ψ″ + β/2 from the plate normal."""
        half_angle = finger_half_angle(finger_angle)
        area = finger_area(half_angle, scenes.radius, self.finger_area_scale)
        incidence = np.where(
            obliquity < scenes.theta1,
            rising_finger_incidence(obliquity, scenes.hinge_opening, half_angle),  # eq 19
            rolling_finger_incidence(half_angle),  # eq 20
        )
        return area, incidence  # (finger_kernel: the same for numbers)

    def force_change(self, contact: Contact) -> tuple[np.ndarray, np.ndarray]:
        drag, lift = self.relief(contact)
        area, incidence = self.finger(contact.obliquity, contact.failure_state[0], contact.scenes)
        finger_force = area * contact.law.stress(contact.speed, incidence)  # eq 16
        return drag + finger_force * np.cos(incidence), lift + finger_force * np.sin(incidence)
