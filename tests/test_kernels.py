"""Each formula once: numba compiles the very functions the numpy path calls, and per scene
the compiled kernels of numbers give the numpy path's vectorised results (issue 23).

Skipped without numba (the optional extra ``pip install plateimpact[fast]``). The states
cover the whole domain of eqs 2–6 (P from before contact to past 2 Rs, θ from 0 to π)
plus the branch surfaces and landmarks themselves, and the test checks that every branch
was visited, so a drift between a kernel's ``if`` and its array twin's mask cannot hide.
"""

from __future__ import annotations

import numpy as np
import pytest

import plateimpact as pi
from plateimpact.model import geometry
from plateimpact.model.resistance import force_on_contact
from plateimpact_plugins import hinge, separation
from plateimpact_plugins.hinge import Hinge
from plateimpact_plugins.plugging import Plugging
from plateimpact_plugins.poncelet import Poncelet, poncelet_stress, poncelet_stress_kernel

numba = pytest.importorskip("numba")

N = 2_000
RTOL = 1e-13  # relative to each quantity's scale: π Rs² [m²], Rs [m], π [rad], force [N]


@pytest.fixture(scope="module")
def compiled():
    """njit of every kernel, callees registered first so that callers compile."""
    kernels = (*geometry.KERNELS, force_on_contact, poncelet_stress, poncelet_stress_kernel)
    kernels += (*separation.KERNELS, *hinge.KERNELS)
    for kernel in kernels:
        numba.extending.register_jitable(kernel)
    jitted = {k.__name__: numba.njit(error_model="numpy")(k) for k in kernels}
    # compile each for numbers now, so that a kernel numba cannot compile fails here
    jitted["contact_geometry_kernel"](1e-3, 0.5, 2e-3)
    return jitted


@pytest.fixture(scope="module")
def states():
    """P [m], θ [rad], Rs [m], V [m/s] and failure columns over the whole domain."""
    rng = np.random.default_rng(23)
    radius = rng.uniform(1e-3, 1e-2, N)
    theta = rng.uniform(0.0, np.pi, N)
    penetration = rng.uniform(-0.05, 2.3, N) * radius
    # landmarks, exactly: both branch surfaces, P = 0, Rs, 2Rs, θ = 0, π/2, π
    k = N // 10
    lift = radius[:k] * np.sin(theta[:k])
    penetration[:k] = np.where(np.arange(k) % 2, radius[:k] - lift, radius[:k] + lift)
    penetration[k : 2 * k] = radius[k : 2 * k] * np.array([0.0, 1.0, 2.0])[np.arange(k) % 3]
    theta[2 * k : 3 * k] = np.array([0.0, 0.5 * np.pi, np.pi])[np.arange(k) % 3]
    failure_angle = rng.uniform(0.2, 1.2, N)
    return {
        "penetration": penetration,
        "obliquity": theta,
        "radius": radius,
        "speed": rng.uniform(0.0, 1500.0, N),
        "a": rng.uniform(1e8, 2e9, N),
        "b": rng.uniform(1e3, 1e4, N),
        "failure_plane_depth": rng.uniform(0.0, 1.0, N) * radius,
        "failure_angle": failure_angle,
        "theta1": 0.5 * np.pi - failure_angle,
        "hinge_opening": failure_angle,
        "finger_angle": rng.uniform(-0.2, 1.0, N) * 2.0 * failure_angle,
        "obliquity_rate": rng.uniform(-2e5, 2e5, N),
    }


def assert_close(actual, expected, scale):
    """|actual − expected| <= RTOL max(|expected|, scale), elementwise; ``scale`` the
    quantity's size (an array or a number), so that values near zero compare absolutely."""
    actual, expected = np.asarray(actual), np.asarray(expected)
    assert actual.shape == expected.shape
    bound = RTOL * np.maximum(np.abs(expected), scale)
    wrong = ~(np.abs(actual - expected) <= bound)  # NaN counts as wrong
    assert not wrong.any(), (
        f"{wrong.sum()} differ, e.g. {actual[wrong][:3]} != {expected[wrong][:3]}"
    )


def per_scene(kernel, *columns, rows=1):
    """The compiled kernel called on each scene's numbers, as arrays (``rows`` outputs)."""
    out = [kernel(*(float(c[i]) if np.ndim(c) else c for c in columns)) for i in range(N)]
    return np.array(out).T if rows > 1 else np.array(out)


def test_every_branch_of_eqs_2_to_6_is_visited(states):
    p, theta, rs = states["penetration"], states["obliquity"], states["radius"]
    alpha1 = geometry.entry_edge_angle(p, rs)
    lower, upper = geometry.branch_surfaces(p, theta, rs)
    assert geometry.in_turnaround_ring(alpha1, theta).sum() > 20
    for side in (lower < 0, (lower > 0) & (upper < 0), upper > 0, lower == 0, upper == 0):
        assert side.sum() > 20
    assert (p < 0).sum() > 5 and (p > 2 * rs).sum() > 20 and (theta == 0).sum() > 20


def test_geometry_kernels_equal_the_array_functions(compiled, states):
    p, theta, rs = states["penetration"], states["obliquity"], states["radius"]
    area, phi = geometry.contact_geometry(p, theta, rs)
    area_c, phi_c = per_scene(compiled["contact_geometry_kernel"], p, theta, rs, rows=2)
    assert_close(area_c, area, np.pi * rs**2)
    assert_close(phi_c, phi, np.pi)
    phi_alone = per_scene(compiled["force_inclination_kernel"], p, theta, rs)
    assert_close(phi_alone, geometry.force_inclination(p, theta, rs), 1.0)
    surfaces = per_scene(compiled["branch_surfaces"], p, theta, rs, rows=2)
    assert_close(surfaces, geometry.branch_margins(p, theta, rs), rs)
    lost = per_scene(compiled["contact_lost_margin"], p, theta, rs)
    assert_close(lost, geometry.contact_lost_margin(p, theta, rs), 1.0)


def poncelet_view(states):
    return pi.SceneBatch.of({k: states[k] for k in ("radius", "a", "b")}, N)


def test_contact_force_kernel_equals_the_laws_force(compiled, states):
    p, theta, speed, rs = (states[k] for k in ("penetration", "obliquity", "speed", "radius"))
    drag, lift = pi.BoundResistance(Poncelet(), poncelet_view(states)).contact_force(
        p, theta, speed
    )
    drag_c, lift_c = _force_per_scene(compiled, states)
    scale = np.pi * rs**2 * (states["a"] + states["b"] * speed**2)  # |F| bound [N]
    assert_close(drag_c, drag, scale)
    assert_close(lift_c, lift, scale)


def _force_per_scene(compiled, states, depth=None):
    """Drag and lift [N] of the compiled force (or relief, below ``depth``) per scene."""
    force = compiled["force_on_contact"]
    geometry_c = compiled["contact_surface_kernel"]
    stress_c = compiled["poncelet_stress_kernel"]
    out = []
    for i in range(N):
        p, theta, speed, rs = (
            float(states[k][i]) for k in ("penetration", "obliquity", "speed", "radius")
        )
        args = (rs, geometry_c, stress_c, np.array([states["a"][i], states["b"][i]], float))
        if depth is None:
            out.append(force(p, theta, speed, *args))
        else:
            drag, lift = force(p - float(depth[i]), theta, speed, *args)  # F′ below the plane
            out.append((-drag, -lift))  # eq 15: the relief
    return np.array(out).T


def failure_contact(states, failure_columns):
    """A Contact over all states for a plane-separation model, with the Poncelet law."""
    scenes = pi.SceneBatch.of({k: states[k] for k in ("radius", *failure_columns)}, N)
    return pi.Contact(
        states["penetration"],
        states["obliquity"],
        states["speed"],
        states["finger_angle"][np.newaxis],
        scenes,
        pi.BoundResistance(Poncelet(), poncelet_view(states)),
        states["obliquity_rate"],
    )


def test_plane_separation_kernels_equal_plugging(compiled, states):
    contact = failure_contact(states, ("failure_plane_depth",))
    depth, rs = states["failure_plane_depth"], states["radius"]
    p, theta = states["penetration"], states["obliquity"]
    drag, lift = Plugging().force_change(contact)
    drag_c, lift_c = _force_per_scene(compiled, states, depth)
    scale = np.pi * rs**2 * (states["a"] + states["b"] * states["speed"] ** 2)
    assert_close(drag_c, drag, scale)
    assert_close(lift_c, lift, scale)
    margin = per_scene(compiled["plane_perforation_margin"], p, theta, rs, depth)
    assert_close(margin, Plugging().perforation_margin(contact), rs)
    surfaces = per_scene(compiled["plane_branch_surfaces"], p, theta, rs, depth, rows=2)
    assert_close(surfaces, Plugging().branch_margins(contact), rs)
    onset = rs * states["failure_angle"]  # any onset penetration [m]
    plane = per_scene(compiled["failure_plane_depth"], rs, states["failure_angle"], onset)
    expected = separation.failure_plane_depth(rs, states["failure_angle"], onset)
    assert_close(plane, expected, rs)


@pytest.mark.parametrize("area_scale", [1.0, 0.37])
def test_finger_kernels_equal_the_hinge(compiled, states, area_scale):
    columns = ("failure_plane_depth", "failure_angle", "theta1", "hinge_opening")
    contact = failure_contact(states, columns)
    model = Hinge(finger_area_scale=area_scale)
    theta, beta, rs = states["obliquity"], states["finger_angle"], states["radius"]
    theta1, opening = states["theta1"], states["hinge_opening"]
    assert 20 < (theta < theta1).sum() < N - 20 and (beta <= 0).sum() > 20  # both branches
    area, incidence = model.finger(theta, beta, contact.scenes)
    kernel = compiled["finger_kernel"]
    area_c, incidence_c = per_scene(kernel, theta, beta, rs, theta1, opening, area_scale, rows=2)
    assert_close(area_c, area, np.pi * rs**2)
    assert_close(incidence_c, incidence, np.pi)
    rate_c = per_scene(
        compiled["finger_rate_kernel"],
        theta,
        beta,
        states["obliquity_rate"],
        states["speed"],
        rs,
        states["failure_angle"],
        theta1,
    )
    rate = model.state_rates(contact)[0]
    assert (rate == 0).sum() > 20 and (rate < 0).sum() > 20  # held or off, and peeling
    assert_close(rate_c, rate, 0.0)
    onset_c = per_scene(compiled["initial_finger_angle"], theta, states["failure_angle"], theta1)
    assert_close(onset_c, model.initial_state(contact)[0], np.pi)
