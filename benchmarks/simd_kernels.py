"""The kernels of benchmarks/simd_lanes.py: the intact plate with Poncelet resistance, one
scene at a time (scalar) and in lanes of scenes side by side (SIMD), for numba.

Both are built from the package's own kernels of numbers (``geometry.KERNELS``,
``force_on_contact``, ``poncelet_stress``; tests/test_kernels.py compiles them the same
way), so the physics is written once here too. The scalar code calls
``contact_surface_kernel``, whose turn-around ring is an ``if``; a lane computes eq 6 in
every lane and the ring (its arctan2 and six sines and cosines) only when one of its
lanes needs it, selected per lane. Every lane loop is ``for j in range(width)`` with
``width`` a run-time argument: LLVM's loop vectorizer turns it into vector code (a
constant trip count is unrolled first, and the SLP vectorizer then left it scalar).

State rows: P [m], Y [m], θ [rad], V [m/s] (as in plateimpact.model.impact). The two
steppers do the same arithmetic in the same order, so without fastmath they give the same
results bit for bit and count the same force evaluations.
"""

from __future__ import annotations

import numba
import numpy as np

from plateimpact.model import geometry
from plateimpact.model.geometry import (
    _clamp,
    contact_lost_margin,
    contact_surface_kernel,
    entry_edge_angle,
    in_turnaround_ring,
    inclination_bisector,
    presented_area,
    ring_inclination,
)
from plateimpact.model.resistance import force_from_stress, force_on_contact, force_on_surface
from plateimpact.solve.compiled import elementary  # noqa: F401  (registers the branch-free functions)
from plateimpact_plugins.dopri5 import DormandPrince54
from plateimpact_plugins.poncelet import poncelet_stress


def stress_of_pair(speed, incidence, pair):
    """Poncelet's σ [N/m²] with its (a, b) as one argument, as a stress kernel takes it."""
    return poncelet_stress(speed, incidence, pair[0], pair[1])


for _kernel in (
    *geometry.KERNELS,
    force_from_stress,
    force_on_surface,
    force_on_contact,
    poncelet_stress,
    stress_of_pair,
):
    numba.extending.register_jitable(_kernel)

# The Dormand-Prince 5(4) tableau (the package's, as compile-time constants) and the
# project's step control (plateimpact.solve.control, plateimpact_plugins.embedded_rk).
STAGES = 7  # six new evaluations per step, the seventh is the next step's first (FSAL)
#: Stage s is evaluated at y + h Σ_m WEIGHTS[s, m] k_m: the rows of A, then B (y_new).
WEIGHTS = np.zeros((STAGES, STAGES - 1))
WEIGHTS[1:6, :5] = DormandPrince54.A[1:6]
WEIGHTS[6] = DormandPrince54.B
E = DormandPrince54.E  # error weights, over all seven stages
SAFETY, MIN_FACTOR, MAX_FACTOR, EXPONENT = 0.9, 0.2, 10.0, -1.0 / 5.0
MAX_STEP, FIRST_STEP = 0.5, 1e-2  # [Rs/Vs]
TURNED_BACK = np.pi - 1e-8  # |θ| [rad] from which θ is held (ImpactModel.TURN_BACK_TOLERANCE)
RICOCHET, EMBEDMENT, UNFINISHED = 1, 2, 0  # plateimpact.Outcome's codes


# -- the force and the rates --------------------------------------------------------------


def scalar_rates(p, theta, v, held, rs, mass, a, b):
    """dy/dt of one scene (ImpactModel.rates for the intact plate): θ < 0 is the mirror
    image of |θ|, and θ is held once it has turned back."""
    side = -1.0 if theta < 0.0 else 1.0
    drag, lift = force_on_contact(
        p, abs(theta), v, rs, contact_surface_kernel, stress_of_pair, (a, b)
    )
    theta_rate = 0.0 if held else side * lift / (mass * v)
    return v * np.cos(theta), v * np.sin(theta), theta_rate, -drag / mass


def lane_forces(pen, obl, speed, start, width, rs, a, b, phi, drag, lift):
    """Drag and lift [N] of the lanes start ... start + width − 1 (eqs 1–6, 22–24):
    ``contact_surface_kernel`` and ``force_on_contact`` with the ring's ``if`` made a
    select. ``phi`` is scratch of ``width``; ``obl`` is |θ|."""
    ring_somewhere = False
    for j in range(width):
        p, t = pen[start + j], abs(obl[start + j])
        alpha1 = entry_edge_angle(p, rs)
        phi[j] = _clamp(inclination_bisector(alpha1, t), 0.0, t)  # eq 6
        ring_somewhere |= in_turnaround_ring(alpha1, t)
    if ring_somewhere:  # rare: deep spheres that have turned outward
        for j in range(width):
            p, t = pen[start + j], abs(obl[start + j])
            alpha1 = entry_edge_angle(p, rs)
            ring_phi = ring_inclination(alpha1, t, inclination_bisector(alpha1, t))
            phi[j] = ring_phi if in_turnaround_ring(alpha1, t) else phi[j]
    for j in range(width):
        p, t, v = pen[start + j], abs(obl[start + j]), speed[start + j]
        incidence = t - phi[j]  # ψ, eq 22
        force = presented_area(p, t, rs, phi[j]) * poncelet_stress(v, incidence, a, b)
        drag[start + j] = force * np.cos(incidence)  # eqs 23, 24
        lift[start + j] = force * np.sin(incidence)


def lane_rates(y, out, held, width, rs, mass, a, b, scratch):
    """dy/dt of every lane into ``out`` (4, width): :func:`scalar_rates` side by side.
    ``scratch`` (3, width): φ, drag, lift."""
    lane_forces(y[0], y[2], y[3], 0, width, rs, a, b, scratch[0], scratch[1], scratch[2])
    for j in range(width):
        theta, v = y[2, j], y[3, j]
        side = -1.0 if theta < 0.0 else 1.0
        out[0, j] = v * np.cos(theta)
        out[1, j] = v * np.sin(theta)
        out[2, j] = 0.0 if held[j] else side * scratch[2, j] / (mass * v)
        out[3, j] = -scratch[1, j] / mass


# -- one scene at a time -------------------------------------------------------------------


def scalar_error_norm(y, y_new, k, h, rtol, scale):
    """max over components of |error| / (rtol max(scale, |y|, |y_new|)) (the project's
    norm: scales Rs, Rs, 1 rad, Vs); NaN propagates."""
    norm = 0.0
    for c in range(4):
        error = 0.0
        for m in range(STAGES):
            if E[m] != 0.0:
                error += E[m] * k[m, c]
        ratio = abs(h * error) / (rtol * max(scale[c], max(abs(y[c]), abs(y_new[c]))))
        norm = ratio if not ratio <= norm else norm
    return norm


def step_factor(norm, after_rejection):
    """0.9 norm^(−1/5) clipped to [0.2, 10], at most 1 after or at a rejection."""
    factor = min(max(SAFETY * norm**EXPONENT, MIN_FACTOR), MAX_FACTOR)
    factor = factor if factor == factor else MIN_FACTOR  # NaN
    return min(factor, 1.0) if after_rejection else factor


def run_scalar(speeds, obliquities, rs, mass, a, b, rtol, rest_fraction, max_steps, out, sample):
    """Every scene to its end, one after the other; returns the force evaluations.
    ``out`` (6, n): outcome, P [m], θ [rad], V [m/s] at the end, steps, evaluations.
    ``sample`` (3, n) or empty: one accepted state per scene, drawn uniformly (reservoir)."""
    k = np.empty((STAGES, 4))
    y, y_new, scale = np.empty(4), np.empty(4), np.empty(4)
    total = 0
    for i in range(speeds.size):
        vs = speeds[i]
        unit, rest = rs / vs, rest_fraction * vs
        y[0], y[1], y[2], y[3] = 0.0, 0.0, obliquities[i], vs
        scale[0], scale[1], scale[2], scale[3] = rs, rs, 1.0, vs
        held, rejected, h, steps, accepted, outcome = False, False, FIRST_STEP * unit, 0, 0, -1
        k[0, 0], k[0, 1], k[0, 2], k[0, 3] = scalar_rates(0.0, y[2], vs, held, rs, mass, a, b)
        evaluations = 1
        while outcome < 0:
            h = min(h, MAX_STEP * unit)
            for s in range(1, STAGES):
                for c in range(4):
                    total_c = 0.0
                    for m in range(s):
                        if WEIGHTS[s, m] != 0.0:  # skipped as plateimpact_plugins does
                            total_c += WEIGHTS[s, m] * k[m, c]
                    y_new[c] = y[c] + h * total_c  # the last stage's is y_new
                k[s, 0], k[s, 1], k[s, 2], k[s, 3] = scalar_rates(
                    y_new[0], y_new[2], y_new[3], held, rs, mass, a, b
                )
            evaluations += STAGES - 1
            steps += 1
            norm = scalar_error_norm(y, y_new, k, h, rtol, scale)
            ok = norm <= 1.0 and np.isfinite(y_new).all()
            h *= step_factor(norm, rejected or not ok)
            rejected = not ok
            if ok:
                y[:] = y_new
                k[0] = k[6]
                accepted += 1
                # numba's own generator: compiled code has no np.random.Generator to call
                if sample.size and np.random.random() * accepted < 1.0:  # noqa: NPY002
                    sample[0, i], sample[1, i], sample[2, i] = y[0], y[2], y[3]
                if contact_lost_margin(y[0], abs(y[2]), rs) >= 0.0:
                    outcome = RICOCHET  # ricochet wins a tie with rest, as in the project
                elif rest - y[3] >= 0.0:
                    outcome = EMBEDMENT
                elif not held and abs(y[2]) - TURNED_BACK >= 0.0:
                    held = True  # a new right-hand side: its first stage anew
                    k[0, 0], k[0, 1], k[0, 2], k[0, 3] = scalar_rates(
                        y[0], y[2], y[3], held, rs, mass, a, b
                    )
                    evaluations += 1
            if outcome < 0 and steps >= max_steps:
                outcome = UNFINISHED
        out[0, i], out[1, i], out[2, i], out[3, i] = outcome, y[0], y[2], y[3]
        out[4, i], out[5, i] = steps, evaluations
        total += evaluations
    return total


# -- lanes of scenes side by side -----------------------------------------------------------


def start_lane(j, i, speeds, obliquities, y, k, scale, real, count, rs, mass, a, b, rest_fraction):
    """Put scene ``i`` into lane ``j``: its initial state and first stage (one evaluation).
    ``real`` rows: h, Rs/Vs, rest speed; ``count`` rows: scene, steps, evaluations."""
    vs = speeds[i]
    real[1, j], real[2, j] = rs / vs, rest_fraction * vs
    real[0, j] = FIRST_STEP * real[1, j]
    y[0, j], y[1, j], y[2, j], y[3, j] = 0.0, 0.0, obliquities[i], vs
    scale[0, j], scale[1, j], scale[2, j], scale[3, j] = rs, rs, 1.0, vs
    k[0, 0, j], k[0, 1, j], k[0, 2, j], k[0, 3, j] = scalar_rates(
        0.0, obliquities[i], vs, False, rs, mass, a, b
    )
    count[0, j], count[1, j], count[2, j] = i, 0, 1


def lane_error_norm(y, y_new, k, h, rtol, scale, norm, error, width):
    """:func:`scalar_error_norm` of every lane into ``norm``; ``error`` is scratch."""
    for j in range(width):
        norm[j] = 0.0
    for c in range(4):
        for j in range(width):
            error[j] = 0.0
        for m in range(STAGES):
            if E[m] != 0.0:
                for j in range(width):
                    error[j] += E[m] * k[m, c, j]
        for j in range(width):
            bound = rtol * max(scale[c, j], max(abs(y[c, j]), abs(y_new[c, j])))
            ratio = abs(h[j] * error[j]) / bound
            norm[j] = ratio if not ratio <= norm[j] else norm[j]


def run_lanes(speeds, obliquities, rs, mass, a, b, rtol, rest_fraction, max_steps, out, width):
    """:func:`run_scalar` (without the sample) with ``width`` scenes stepped together, each
    lane with its own step size and accept/reject mask; a lane whose scene ends takes the
    next scene of the queue. Returns the force evaluations."""
    y, y_new = np.zeros((4, width)), np.zeros((4, width))
    y[3, :] = 1.0  # a lane that never gets a scene stays at rest, finite
    k, scale = np.zeros((STAGES, 4, width)), np.ones((4, width))
    real, scratch = np.ones((4, width)), np.zeros((3, width))  # h, Rs/Vs, rest, norm
    count = np.zeros((3, width), np.int64)  # scene, steps, evaluations
    held, rejected = np.zeros(width, np.bool_), np.zeros(width, np.bool_)
    active, accepted = np.zeros(width, np.bool_), np.zeros(width, np.bool_)
    flagged = np.zeros(width, np.bool_)
    queued, running, total = 0, 0, 0
    for j in range(min(width, speeds.size)):
        start_lane(
            j, j, speeds, obliquities, y, k, scale, real, count, rs, mass, a, b, rest_fraction
        )
        active[j], queued, running = True, j + 1, j + 1
    while running > 0:
        h, norm = real[0], real[3]
        for j in range(width):
            h[j] = min(h[j], MAX_STEP * real[1, j])
        for s in range(1, STAGES):
            for c in range(4):
                for j in range(width):
                    y_new[c, j] = 0.0
                for m in range(s):
                    if WEIGHTS[s, m] != 0.0:
                        for j in range(width):
                            y_new[c, j] += WEIGHTS[s, m] * k[m, c, j]
                for j in range(width):
                    y_new[c, j] = y[c, j] + h[j] * y_new[c, j]
            lane_rates(y_new, k[s], held, width, rs, mass, a, b, scratch)
        lane_error_norm(y, y_new, k, h, rtol, scale, norm, scratch[0], width)
        flagged_count = 0
        for j in range(width):  # accept or reject, per lane, by selects
            finite = np.isfinite(y_new[0, j]) & np.isfinite(y_new[1, j])
            finite &= np.isfinite(y_new[2, j]) & np.isfinite(y_new[3, j])
            good = (norm[j] <= 1.0) & finite
            h[j] *= step_factor(norm[j], rejected[j] | (not good))
            rejected[j] = not good
            accepted[j] = good & active[j]
            count[1, j] += active[j]
            count[2, j] += (STAGES - 1) * active[j]
        # separate loops: LLVM vectorizes none of them when the copies share one
        for c in range(4):
            for j in range(width):
                y[c, j] = y_new[c, j] if accepted[j] else y[c, j]
        for c in range(4):
            for j in range(width):
                k[0, c, j] = k[6, c, j] if accepted[j] else k[0, c, j]
        for j in range(width):
            event = contact_lost_margin(y[0, j], abs(y[2, j]), rs) >= 0.0
            event |= real[2, j] - y[3, j] >= 0.0
            event |= (not held[j]) & (abs(y[2, j]) - TURNED_BACK >= 0.0)
            flagged[j] = active[j] & ((accepted[j] & event) | (count[1, j] >= max_steps))
            flagged_count += flagged[j]
        if flagged_count == 0:
            continue
        for j in range(width):  # the rare lanes with an event: scalar code, as run_scalar
            if not flagged[j]:
                continue
            outcome = -1
            if accepted[j]:
                if contact_lost_margin(y[0, j], abs(y[2, j]), rs) >= 0.0:
                    outcome = RICOCHET
                elif real[2, j] - y[3, j] >= 0.0:
                    outcome = EMBEDMENT
                elif not held[j] and abs(y[2, j]) - TURNED_BACK >= 0.0:
                    held[j] = True
                    k[0, 0, j], k[0, 1, j], k[0, 2, j], k[0, 3, j] = scalar_rates(
                        y[0, j], y[2, j], y[3, j], True, rs, mass, a, b
                    )
                    count[2, j] += 1
            if outcome < 0 and count[1, j] >= max_steps:
                outcome = UNFINISHED
            if outcome < 0:
                continue
            i = count[0, j]
            out[0, i], out[1, i], out[2, i], out[3, i] = outcome, y[0, j], y[2, j], y[3, j]
            out[4, i], out[5, i] = count[1, j], count[2, j]
            total += count[2, j]
            held[j] = rejected[j] = False
            if queued < speeds.size:
                start_lane(
                    j,
                    queued,
                    speeds,
                    obliquities,
                    y,
                    k,
                    scale,
                    real,
                    count,
                    rs,
                    mass,
                    a,
                    b,
                    rest_fraction,
                )
                queued += 1
            else:
                active[j] = False
                running -= 1
    return total


# -- the force alone, over an array of states ---------------------------------------------


def scalar_forces(pen, obl, speed, rs, a, b, drag, lift):
    """Drag and lift [N] of every state, one at a time (the kernel the compiled path calls)."""
    for i in range(pen.size):
        drag[i], lift[i] = force_on_contact(
            pen[i], obl[i], speed[i], rs, contact_surface_kernel, stress_of_pair, (a, b)
        )


def lane_forces_in_blocks(pen, obl, speed, rs, a, b, drag, lift, width, phi):
    """The same, ``width`` consecutive states at a time (:func:`lane_forces`)."""
    whole = pen.size - pen.size % width
    for start in range(0, whole, width):
        lane_forces(pen, obl, speed, start, width, rs, a, b, phi, drag, lift)
    lane_forces(pen, obl, speed, whole, pen.size - whole, rs, a, b, phi, drag, lift)


# Helpers with lane loops are inlined into each caller's numba IR, so that every compiled
# variant vectorizes them afresh at its own width (a callee compiled once would be reused,
# vectorized at the first caller's width); the rest are compiled once and shared.
for _helper in (lane_forces, lane_rates, lane_error_norm):
    numba.extending.register_jitable(inline="always")(_helper)
for _helper in (scalar_rates, scalar_error_norm, step_factor, start_lane):
    numba.extending.register_jitable(_helper)
