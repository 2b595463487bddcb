"""The right-hand side and the margins of a lane of scenes: :mod:`.motion`'s functions for
every lane at once, stored lane-major (``src[row, lane]``), calling the same formulas.

Each loop over the lanes calls only inlined, branch-free code (the geometry's eq-6 branch
and :mod:`plateimpact.elementary`'s functions), so LLVM vectorises it: a pass over the
lanes costs a few scenes' worth. The relieved force of a failed plate (eqs 9–15) is a
second such pass. The law's stress and a failed plate's perforation and branch margins
are inline copies of the plug-ins' kernels on each lane's constants (lane-major), in the
same loops. What only some lanes need is then done lane by lane by the scalar kernels:
what a failure model adds on top of its relief, the failure state's rates, and the
turn-around ring of eq 6, which the scalar rates redo whole. A lane's numbers are
therefore the scalar path's, bit for bit (tested).

``lanes`` is a :class:`~.lane_store.Lanes`; ``scenes`` a :class:`~.lane_store.Batch` of
the batch's columns.
"""

from __future__ import annotations

from typing import Any

import numpy as np

from ...model.events import AT_REST, CONTACT_LOST, ONSET, PERFORATED, TURNED_BACK
from ...model.geometry import HALF_PI, _surface, branch_surfaces, eq6_inclination
from ...model.kernels import KernelContact
from ...model.resistance import force_from_stress
from .lane_store import (
    DRAG,
    EXTRA_DRAG,
    EXTRA_LIFT,
    FAILED,
    HELD,
    LIFT,
    MASS,
    NO_DEPTH,
    ONSET_PENETRATION,
    RADIUS,
    RELIEF_DEPTH,
    RELIEVED_RING,
    REST_SPEED,
    RING,
    WIDTH,
    Batch,
    Lanes,
    gather,
    lane_twin,
    scatter,
    scene_of,
)
from .motion import (
    P_,
    STATE,
    THETA_,
    V_,
    Y_,
    CompiledModel,
    contact_of,
    failure_state_rates,
    kinematic_margins,
    motion,
    rates,
)

# The contact surface, inlined where the vector loop calls it (lane_twin): too large for
# LLVM's inliner. The small formulas the loops call LLVM inlines itself.
_eq6_inclination = lane_twin(eq6_inclination)
_surface_of = lane_twin(_surface)


def surface_of_lane(surface: Any, lane: int) -> tuple[float, ...]:
    """One lane's contact surface (A, φ, cos ψ, sin ψ, sin θ, cos θ) from ``surface``
    (6, lanes), as the scalar formulas take it."""
    return (
        surface[0, lane], surface[1, lane], surface[2, lane], surface[3, lane],
        surface[4, lane], surface[5, lane],
    )  # fmt: skip


def lane_surfaces(radius: Any, src: Any, depth: Any, surface: Any, ring: Any) -> None:
    """The contact surface (A, φ, cos ψ, sin ψ, sin θ, cos θ) below the plane ``depth``
    [m] above each lane's deepest point (P − depth for P: 0 for the intact surface, the
    failure plane's depth for the relieved one) at every lane's row of ``src``, with
    sphere radii ``radius`` [m], into ``surface`` (6, lanes), φ from eq 6, and which
    lanes lie in the ring instead. (Each lane function takes only the arrays it uses:
    numba passes every array as separate arguments, which costs at each call.)"""
    for lane in range(WIDTH):
        penetration = src[P_, lane] - depth[lane]
        obliquity, sphere = np.abs(src[THETA_, lane]), radius[lane]
        phi, in_ring = _eq6_inclination(penetration, obliquity, sphere)[:2]
        area, phi, cos_psi, sin_psi, sin_t, cos_t = _surface_of(penetration, obliquity, sphere, phi)
        surface[0, lane], surface[1, lane], surface[2, lane] = area, phi, cos_psi
        surface[3, lane], surface[4, lane], surface[5, lane] = sin_psi, sin_t, cos_t
        ring[lane] = in_ring


def lane_forces(
    model: CompiledModel, law: Any, src: Any, surface: Any, drag: Any, lift: Any
) -> None:
    """The law's drag and lift [N] on each lane's ``surface`` (:func:`force_on_surface`):
    its stress, an inline copy of the law's kernel, on each lane's constants ``law``
    (lane-major), and the force, all in one vector loop."""
    for lane in range(WIDTH):
        incidence = np.abs(src[THETA_, lane]) - surface[1, lane]
        stress = model.stress_in_lanes(src[V_, lane], incidence, law[:, lane])
        here = surface_of_lane(surface, lane)
        drag[lane], lift[lane] = force_from_stress(here, stress)


def lane_failure_forces(model: CompiledModel, lanes: Lanes, scenes: Batch, src: Any) -> None:
    """Each failed lane's change of drag and lift (:func:`~.motion.failure_force`) added
    to its drag and lift (rows DRAG, LIFT of ``lanes.value``): −F′ below the relief
    plane for every lane together, what ``force_change`` adds lane by lane."""
    value, flag = lanes.value, lanes.flag
    extra_drag, extra_lift = value[EXTRA_DRAG], value[EXTRA_LIFT]
    relief = model.relief_column >= 0
    if relief:
        depth, ring = value[RELIEF_DEPTH], flag[RELIEVED_RING]
        lane_surfaces(value[RADIUS], src, depth, lanes.relieved, ring)
        lane_forces(model, lanes.law, src, lanes.relieved, extra_drag, extra_lift)
        for lane in range(WIDTH):
            extra_drag[lane], extra_lift[lane] = -extra_drag[lane], -extra_lift[lane]  # eq 15
    if model.force_besides_relief or not relief:
        for lane in range(WIDTH):
            i = lanes.scene[lane]
            if i >= 0 and flag[FAILED, lane]:
                y = gather(src, lane, lanes.one_state)
                contact = contact_of(model, scene_of(scenes, i), y, np.abs(y[THETA_]), np.nan)
                more_drag, more_lift = model.force_change(contact)
                if relief:
                    more_drag, more_lift = (
                        extra_drag[lane] + more_drag,
                        extra_lift[lane] + more_lift,
                    )
                extra_drag[lane], extra_lift[lane] = more_drag, more_lift
    drag, lift = value[DRAG], value[LIFT]
    for lane in range(WIDTH):
        failed = flag[FAILED, lane]
        drag[lane] = drag[lane] + extra_drag[lane] if failed else drag[lane]
        lift[lane] = lift[lane] + extra_lift[lane] if failed else lift[lane]


def lane_rates(model: CompiledModel, lanes: Lanes, scenes: Batch, src: Any, out: Any) -> None:
    """dy/dt at every lane's row of ``src`` into ``out`` (:func:`~.motion.rates`)."""
    value, flag = lanes.value, lanes.flag
    surface, drag, lift = lanes.surface, value[DRAG], value[LIFT]
    lane_surfaces(value[RADIUS], src, value[NO_DEPTH], surface, flag[RING])
    lane_forces(model, lanes.law, src, surface, drag, lift)
    any_failed = False
    for lane in range(WIDTH):
        any_failed = any_failed | (flag[FAILED, lane] & (lanes.scene[lane] >= 0))
    if any_failed:
        lane_failure_forces(model, lanes, scenes, src)
    for lane in range(WIDTH):
        theta, speed = src[THETA_, lane], src[V_, lane]
        side = -1.0 if theta < 0.0 else 1.0
        here = surface_of_lane(surface, lane)
        p_rate, y_rate, theta_rate, v_rate = motion(
            here, drag[lane], lift[lane], side, speed, value[MASS, lane], flag[HELD, lane]
        )
        out[P_, lane], out[Y_, lane] = p_rate, y_rate
        out[THETA_, lane], out[V_, lane] = theta_rate, v_rate
    for row in range(STATE, out.shape[0]):
        for lane in range(WIDTH):
            out[row, lane] = 0.0
    relief = model.relief_column >= 0
    for lane in range(WIDTH):
        i = lanes.scene[lane]
        if i < 0:
            continue
        failed = flag[FAILED, lane]
        if flag[RING, lane] or (failed and relief and flag[RELIEVED_RING, lane]):
            y, rate = gather(src, lane, lanes.one_state), lanes.one_rate
            rates(model, scene_of(scenes, i), y, failed, flag[HELD, lane], rate)
            scatter(rate, out, lane)
        elif failed and out.shape[0] > STATE:  # the failure state's rates
            y, rate = gather(src, lane, lanes.one_state), lanes.one_rate
            failure_state_rates(model, scene_of(scenes, i), y, out[THETA_, lane], rate[STATE:])
            for row in range(STATE, out.shape[0]):
                out[row, lane] = rate[row]


def lane_contact(
    model: CompiledModel, lanes: Lanes, src: Any, lane: int, obliquity: float
) -> KernelContact:
    """The failure model's view of a lane's row of ``src`` at |θ| = ``obliquity``
    (:func:`~.motion.contact_of`), its constants read lane-major."""
    return KernelContact(
        src[P_, lane], obliquity, src[V_, lane], np.nan, src[STATE:, lane],
        lanes.constants[:, lane], lanes.value[RADIUS, lane], model.stress,
        lanes.law[:, lane],
    )  # fmt: skip


def lane_branch_margins(model: CompiledModel, lanes: Lanes, src: Any, out: Any) -> None:
    """The branch margins at every lane's row of ``src`` into ``out`` (rows, lanes)
    (:func:`~.motion.branch_margins`): the failure model's rows by its kernel's inline
    copy for every lane, NaN where the plate is intact."""
    value, flag = lanes.value, lanes.flag
    for lane in range(WIDTH):
        first, second = branch_surfaces(
            src[P_, lane], np.abs(src[THETA_, lane]), value[RADIUS, lane]
        )
        out[0, lane], out[1, lane] = first, second
    if out.shape[0] > 2:
        for lane in range(WIDTH):
            contact = lane_contact(model, lanes, src, lane, np.abs(src[THETA_, lane]))
            model.branch_margins_in_lanes(contact, out[2:, lane])
        for row in range(2, out.shape[0]):
            for lane in range(WIDTH):
                out[row, lane] = out[row, lane] if flag[FAILED, lane] else np.nan


def lane_event_margins(
    model: CompiledModel, lanes: Lanes, scenes: Batch, src: Any, out: Any
) -> None:
    """The event margins at every lane's row of ``src`` into ``out`` (events, lanes)
    (:func:`~.motion.event_margins`): perforation by the failure model's kernel's inline
    copy for every lane, −inf where the plate is intact or θ >= 90°."""
    value, flag = lanes.value, lanes.flag
    for lane in range(WIDTH):
        onset, lost, rest, back = kinematic_margins(
            src[P_, lane], np.abs(src[THETA_, lane]), src[V_, lane], value[RADIUS, lane],
            value[REST_SPEED, lane], value[ONSET_PENETRATION, lane], scenes.turn_back_limit,
            scenes.adds_onset, flag[FAILED, lane], flag[HELD, lane],
        )  # fmt: skip
        out[ONSET, lane], out[CONTACT_LOST, lane] = onset, lost
        out[AT_REST, lane], out[TURNED_BACK, lane] = rest, back
        out[PERFORATED, lane] = -np.inf
    if scenes.adds_perforation:
        for lane in range(WIDTH):
            obliquity = np.abs(src[THETA_, lane])
            margin = model.perforation_in_lanes(lane_contact(model, lanes, src, lane, obliquity))
            perforating = flag[FAILED, lane] & (obliquity < HALF_PI)
            out[PERFORATED, lane] = margin if perforating else -np.inf


#: The functions of numbers a compiled path compiles (callees before callers).
KERNELS = (
    surface_of_lane,
    lane_surfaces,
    lane_forces,
    lane_failure_forces,
    lane_rates,
    lane_branch_margins,
    lane_event_margins,
)
#: Inlined where called.
INLINE = (_eq6_inclination, _surface_of, lane_contact)
