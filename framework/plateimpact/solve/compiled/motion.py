"""One scene's right-hand side and margins, as numbers: the compiled twin of
:meth:`ImpactModel.rates <plateimpact.model.impact.ImpactModel.rates>`,
``event_margins`` and ``branch_margins``, calling the same formulas (eqs 1-6, 15-30).

``model`` is a :class:`CompiledModel` (the plug-ins' kernels), ``scene`` a
:class:`SceneConstants`; ``y`` the state P [m], Y [m], θ [rad], V [m/s], then the failure
state. Results are written into ``out`` (no allocation in the step loop).
"""

from __future__ import annotations

from typing import Any, NamedTuple

import numpy as np

from ...model.events import AT_REST, CONTACT_LOST, ONSET, PERFORATED, TURNED_BACK
from ...model.geometry import HALF_PI, branch_surfaces, contact_lost_margin, contact_surface_kernel
from ...model.kernels import KernelContact
from ...model.resistance import force_on_contact, force_on_surface

P_, Y_, THETA_, V_ = 0, 1, 2, 3  # rows of y (plateimpact.model.impact.PENETRATION ...)
STATE = 4  # first failure-state row (KINEMATIC_STATE)


class CompiledModel(NamedTuple):
    """The plug-ins' kernels: the law's stress, the failure model's :class:`FailureKernels`
    (its ``relief_column``, and whether its ``force_change`` adds anything to a relief),
    and the inline copies of the stress and the margins that the lanes' vector loops
    call (:func:`~.program.lane_kernel`)."""

    stress: Any
    force_change: Any
    perforation_margin: Any
    branch_margins: Any
    initial_state: Any
    state_rates: Any
    relief_column: int
    force_besides_relief: bool
    stress_in_lanes: Any
    perforation_in_lanes: Any
    branch_margins_in_lanes: Any


class SceneConstants(NamedTuple):
    """One scene's constants: Rs [m], m [kg], the rest speed [m/s], the onset penetration
    [m], θ held at turn-back [rad] and the limit that counts as turned back [rad], whether
    the failure model adds onset and perforation, and the two plug-ins' kernel rows."""

    radius: float
    mass: float
    rest_speed: float
    onset_penetration: float
    max_obliquity: float
    turn_back_limit: float
    adds_onset: bool
    adds_perforation: bool
    constants: Any
    law_constants: Any


def contact_of(
    model: CompiledModel, scene: SceneConstants, y: Any, obliquity: float, obliquity_rate: float
) -> KernelContact:
    """The failure model's view of the scene at ``y``, at ``obliquity`` θ >= 0 [rad]."""
    return KernelContact(
        y[P_], obliquity, y[V_], obliquity_rate, y[STATE:], scene.constants, scene.radius,
        model.stress, scene.law_constants,
    )  # fmt: skip


def failure_force(
    model: CompiledModel, scene: SceneConstants, y: Any, obliquity: float
) -> tuple[float, float]:
    """The failure model's change of drag and lift [N] at ``y``, at |θ| = ``obliquity``
    [rad] (its ``force_change``): −F′ below its relief plane if it declares one (eqs
    9–15), plus its ``force_change``."""
    if model.relief_column < 0:
        return model.force_change(contact_of(model, scene, y, obliquity, np.nan))
    depth = scene.constants[model.relief_column]
    relieved_drag, relieved_lift = force_on_contact(
        y[P_] - depth, obliquity, y[V_], scene.radius, contact_surface_kernel, model.stress,
        scene.law_constants,
    )  # fmt: skip
    if not model.force_besides_relief:
        return -relieved_drag, -relieved_lift  # eq 15
    extra_drag, extra_lift = model.force_change(contact_of(model, scene, y, obliquity, np.nan))
    return -relieved_drag + extra_drag, -relieved_lift + extra_lift


def failure_state_rates(
    model: CompiledModel, scene: SceneConstants, y: Any, obliquity_rate: float, out: Any
) -> None:
    """The failure state's rates [unit/s] into ``out`` at ``y``, where θ changes at
    ``obliquity_rate`` [rad/s]: the failure model sees the mirror image for θ < 0, |θ|
    and d|θ|/dt."""
    side = -1.0 if y[THETA_] < 0.0 else 1.0
    contact = contact_of(model, scene, y, side * y[THETA_], side * obliquity_rate)
    model.state_rates(contact, out)


def motion(
    surface: Any, drag: float, lift: float, side: float, speed: float, mass: float, held: bool
) -> tuple[float, float, float, float]:
    """dP/dt [m/s], dY/dt [m/s], dθ/dt [rad/s] and dV/dt [m/s²] (eqs 25–28) from the
    contact ``surface`` at |θ|, the drag and lift [N] on it at |θ|, the side of θ (±1),
    the speed V [m/s] and the mass m [kg]; θ does not turn once held at 180°."""
    obliquity_rate = 0.0 if held else (side * lift) / (mass * speed)
    # cos θ = cos |θ| and sin θ = side · sin |θ| exactly (cos is even, sin odd): the
    # surface's own, not two more evaluations
    return speed * surface[5], speed * (side * surface[4]), obliquity_rate, -drag / mass


def rates(
    model: CompiledModel, scene: SceneConstants, y: Any, failed: bool, held: bool, out: Any
) -> None:
    """dy/dt into ``out`` (:meth:`ImpactModel.rates`): θ < 0 is the mirror image of |θ|."""
    theta, speed = y[THETA_], y[V_]
    side = -1.0 if theta < 0.0 else 1.0
    obliquity = np.abs(theta)
    surface = contact_surface_kernel(y[P_], obliquity, scene.radius)
    drag, lift = force_on_surface(surface, obliquity, speed, model.stress, scene.law_constants)
    if failed:
        extra_drag, extra_lift = failure_force(model, scene, y, obliquity)
        drag, lift = drag + extra_drag, lift + extra_lift
    out[P_], out[Y_], out[THETA_], out[V_] = motion(
        surface, drag, lift, side, speed, scene.mass, held
    )
    if failed:
        failure_state_rates(model, scene, y, out[THETA_], out[STATE:])
    else:
        for row in range(STATE, y.size):
            out[row] = 0.0


def event_margins(
    model: CompiledModel, scene: SceneConstants, y: Any, failed: bool, held: bool, out: Any
) -> None:
    """The event margins into ``out`` (:meth:`ImpactModel.event_margins`, every row)."""
    penetration, obliquity = y[P_], np.abs(y[THETA_])
    out[ONSET], out[CONTACT_LOST], out[AT_REST], out[TURNED_BACK] = kinematic_margins(
        penetration, obliquity, y[V_], scene.radius, scene.rest_speed,
        scene.onset_penetration, scene.turn_back_limit, scene.adds_onset, failed, held,
    )  # fmt: skip
    if scene.adds_perforation and failed and obliquity < HALF_PI:
        out[PERFORATED] = model.perforation_margin(contact_of(model, scene, y, obliquity, np.nan))
    else:
        out[PERFORATED] = -np.inf


def kinematic_margins(
    penetration: float, obliquity: float, speed: float, radius: float, rest_speed: float,
    onset_penetration: float, turn_back_limit: float, adds_onset: bool, failed: bool,
    held: bool,
) -> tuple[float, float, float, float]:  # fmt: skip
    """The margins of failure onset, loss of contact, rest and turn-back at P [m],
    |θ| [rad] and V [m/s] (−inf where the event cannot happen): what every failure model
    shares of :func:`event_margins`, as plain arithmetic."""
    onset = penetration - onset_penetration if adds_onset and not failed else -np.inf
    contact_lost = contact_lost_margin(penetration, obliquity, radius)
    turned_back = -np.inf if held else obliquity - turn_back_limit
    return onset, contact_lost, rest_speed - speed, turned_back


def branch_margins(
    model: CompiledModel, scene: SceneConstants, y: Any, failed: bool, out: Any
) -> None:
    """The branch margins into ``out`` (:meth:`ImpactModel.branch_margins`): the
    geometry's two rows, then the failure model's (NaN while the plate is intact)."""
    obliquity = np.abs(y[THETA_])
    out[0], out[1] = branch_surfaces(y[P_], obliquity, scene.radius)
    if failed:
        model.branch_margins(contact_of(model, scene, y, obliquity, np.nan), out[2:])
    else:
        for row in range(2, out.size):
            out[row] = np.nan


#: The functions of numbers a compiled path compiles (callees before callers).
KERNELS = (
    contact_of,
    failure_force,
    failure_state_rates,
    motion,
    rates,
    kinematic_margins,
    event_margins,
    branch_margins,
)
