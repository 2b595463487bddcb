"""Contact geometry of a sphere in a plate (report eqs 2–6, reused as eqs 9–13).

Conventions (docs/model.md): the plate's front surface is the plane z = 0 with z growing
into the plate; the penetration P [m] is the depth of the sphere's deepest point, so the
centre is at depth P − Rs; the obliquity θ [rad] is the angle of the velocity from the
inward normal (0 normal incidence, π/2 grazing, π straight back out).

The **contact surface** is the part of the sphere that is below the front surface and on
the forward hemisphere. Its projection on the contact plane is the presented area A; the
force acts along the contact-plane normal, at the inclination φ from the plate normal.

Each formula is written once, in numpy ufuncs and arithmetic only, so that the same
function runs on arrays (one value per scene, the numpy path) and on numbers (numba
compiles it for a per-scene loop, the compiled path) with the same results. Where a
formula switches branch per scene (the turn-around ring of eq 6), an array function
selects with a mask and a ``*_kernel`` twin with an ``if``, both calling the same
formulas; :data:`KERNELS` lists what a compiled path compiles. Square roots, sines,
cosines and arccos come from :mod:`plateimpact.model.elementary` (numpy's on arrays,
branch-free polynomials when compiled, so that lanes of scenes vectorise). All
arccos/arcsin arguments are clamped to [−1, 1]: they leave it in legitimate states
(docs/model.md §2, "Clamps"), and the clamped values are the report's own special cases
("then Γe = 2π", "then Γs = 0").
For the plugging relief (eqs 9–13), call the same functions with P − h in place of P.
"""

from __future__ import annotations

from typing import Any

import numpy as np

from .elementary import arccos, sin, sincos, sqrt

HALF_PI = 0.5 * np.pi
TWO_PI = 2.0 * np.pi


def _clamp(value: Any, low: Any, high: Any) -> Any:
    """np.clip at a third of its call overhead (the geometry runs six times a step), and a
    form numba compiles for numbers too."""
    return np.minimum(np.maximum(value, low), high)


def embedment_radius_squared(penetration: Any, radius: Any) -> Any:
    """Re², the squared radius of the circle cut by the front plane (eq 3) [m²].

    Zero when the sphere does not reach the plane (P <= 0) or has passed it (P >= 2 Rs).
    """
    return np.maximum(penetration * (2.0 * radius - penetration), 0.0)


def entry_edge_angle(penetration: Any, radius: Any) -> Any:
    """α1 [rad]: angle, at the centre and from the inward normal, of the point where the
    front surface cuts the sphere in the plane of motion. 0 at first contact, π/2 when
    the centre reaches the surface, π once the sphere is wholly below it."""
    return arccos(_clamp((radius - penetration) / radius, -1.0, 1.0))


def inclination_bisector(alpha1: Any, obliquity: Any) -> Any:
    """½[α1 + θ − π/2] [rad], the bisector of the contact arc's ends α1 and θ − π/2 (eq 6
    before its clamp), from α1 and the obliquity θ [rad]."""
    return 0.5 * (alpha1 + obliquity - HALF_PI)


def in_turnaround_ring(alpha1: Any, obliquity: Any) -> Any:
    """True where a deep sphere that has turned outward touches the plate on both sides of
    its entry hole (θ + π/2 > 2π − α1), where eq 6 gives way to :func:`ring_inclination`."""
    return obliquity + HALF_PI > TWO_PI - alpha1


def ring_inclination(alpha1: Any, obliquity: Any, bisector: Any) -> Any:
    """φ [rad] in the turn-around ring: the normal to the sum of the chords of the two
    contact arcs (θ − π/2, α1) and (2π − α1, θ + π/2), from α1, θ [rad] and the eq 6
    ``bisector`` (the first chord's normal)."""
    first = np.sin(0.5 * (alpha1 - obliquity + HALF_PI))  # chord lengths / 2Rs
    second = np.sin(0.5 * (obliquity + alpha1 - 1.5 * np.pi))
    second_normal = 0.5 * (obliquity + 2.5 * np.pi - alpha1)
    ring_phi = np.arctan2(
        first * np.sin(bisector) + second * np.sin(second_normal),
        first * np.cos(bisector) + second * np.cos(second_normal),
    )
    # φ <= θ holds analytically (the longer arc lies behind the path); the clip only
    # removes arctan2 round-off near θ = π, where the two chords nearly cancel.
    return np.minimum(ring_phi + TWO_PI * (ring_phi < 0.0), obliquity)


def force_inclination(penetration: Any, obliquity: Any, radius: Any) -> np.ndarray:
    """φ [rad], the angle of the contact-plane normal (the force) from the plate normal;
    ``penetration`` P [m], ``obliquity`` θ [rad] and ``radius`` Rs [m], arrays with one
    value per scene (:func:`force_inclination_kernel` is the same for numbers).

    The contact chord joins the two ends of the contact arc in the plane of motion; φ is
    its normal, i.e. the bisector of the ends. Eq 6 is that bisector with the upper end at
    α1 (front surface) and the lower end at θ − π/2 (edge of the forward hemisphere):
    φ = ½[θ + arcsin((P − Rs)/Rs)], since arcsin((P − Rs)/Rs) = α1 − π/2. The report's
    clamp 0 <= φ <= θ is the case where an end lies on the other boundary.

    One case the report does not cover (docs/model.md, "the turn-around ring"): a deep
    sphere that has turned outward (θ > 3π/2 − α1) touches the plate on both sides of
    the hole it came in by, so its contact arc has two pieces. Then the force is normal
    to the sum of the two chords. This reduces to eq 6 when the second piece has zero
    length (so φ is continuous) and gives φ = θ, no lift, at θ = π, where the contact is
    symmetric about the path.
    """
    alpha1 = entry_edge_angle(penetration, radius)
    bisector = inclination_bisector(alpha1, obliquity)
    phi = _clamp(bisector, 0.0, obliquity)  # eq 6
    ring = in_turnaround_ring(alpha1, obliquity)
    if ring.any():  # rare: the ring's arctan2 only where it applies
        phi[ring] = ring_inclination(alpha1[ring], obliquity[ring], bisector[ring])
    return phi


def force_inclination_kernel(penetration: float, obliquity: float, radius: float) -> float:
    """:func:`force_inclination` of numbers [rad], for a compiled path: the same formulas,
    selected per scene."""
    phi, ring, alpha1, bisector = eq6_inclination(penetration, obliquity, radius)
    if ring:
        return ring_inclination(alpha1, obliquity, bisector)
    return phi


def eq6_inclination(
    penetration: float, obliquity: float, radius: float
) -> tuple[float, bool, float, float]:
    """φ [rad] of eq 6 (clamped to [0, θ]), whether the state lies in the turn-around
    ring instead (where :func:`ring_inclination` applies), α1 and the bisector [rad]:
    without a branch, so that a loop over lanes of scenes vectorises it."""
    alpha1 = entry_edge_angle(penetration, radius)
    bisector = inclination_bisector(alpha1, obliquity)
    ring = in_turnaround_ring(alpha1, obliquity)
    return _clamp(bisector, 0.0, obliquity), ring, alpha1, bisector


def limit_ratio(numerator: Any, denominator: Any) -> Any:
    """numerator/denominator clipped to [−1, 1], for denominator >= 0, with the limit at
    denominator = 0: ±1 by the sign of the numerator, and 0 for 0/0 (the limit θ → 0 at
    P = Rs). A zero numerator divides by denominator + 1, so 0/0 never arises; a zero
    denominator otherwise gives ±inf, which clips to ±1 (callers on arrays silence the
    divide warning)."""
    ratio = numerator / (denominator + (numerator == 0.0))
    return _clamp(ratio, -1.0, 1.0)


def presented_area(penetration: Any, obliquity: Any, radius: Any, inclination: Any) -> Any:
    """Presented area A [m²] (eq 2) at ``penetration`` P [m], ``obliquity`` θ [rad] in
    [0, π], ``radius`` Rs [m] and force ``inclination`` φ [rad]: the formula once, on
    numbers or arrays (numpy ufuncs only, so a compiled path compiles this very function).

    A is the projection of the contact surface on the contact plane. By the divergence
    theorem it equals the projections of the two flat faces that close the contact
    surface: the forward segment of the front-plane disc (radius Re, central angle Γe,
    eq 4) and the below-surface segment of the great disc normal to the velocity (radius
    Rs, central angle Γs, eq 5).
    """
    return _surface(penetration, obliquity, radius, inclination)[0]


def _surface(
    penetration: Any, obliquity: Any, radius: Any, inclination: Any
) -> tuple[Any, Any, Any, Any, Any, Any]:
    """A [m²] (eq 2), φ [rad], cos ψ and sin ψ of the incidence ψ = θ − φ (eq 22), and
    sin θ, cos θ, with each sine and cosine evaluated once: the force needs them all
    (eqs 2, 23, 24), and the motion sin θ and cos θ (eqs 25, 26)."""
    sin_t, cos_t = sincos(obliquity)
    sin_phi, cos_phi = sincos(inclination)
    cos_psi = cos_t * cos_phi + sin_t * sin_phi  # cos(θ − φ)
    sin_psi = sin_t * cos_phi - cos_t * sin_phi  # sin(θ − φ)
    centre_height = radius - penetration  # height of the centre above the front plane
    re_squared = embedment_radius_squared(penetration, radius)
    # eq 4, (Rs − P)/(Re tan θ) written with sin and cos so that θ = 0 is a limit.
    ratio_e = limit_ratio(centre_height * cos_t, sqrt(re_squared) * sin_t)
    ratio_s = limit_ratio(centre_height, radius * sin_t)  # eq 5
    # Γ − sin Γ for Γe = 2π − 2 arccos r and Γs = 2 arccos r, with sin(2 arccos r) written
    # as 2 r √(1 − r²): the same values without two more sine evaluations.
    chord_e = 2.0 * ratio_e * sqrt(1.0 - ratio_e * ratio_e)
    chord_s = 2.0 * ratio_s * sqrt(1.0 - ratio_s * ratio_s)
    segment_e = TWO_PI - 2.0 * arccos(ratio_e) + chord_e  # Γe − sin Γe
    segment_s = 2.0 * arccos(ratio_s) - chord_s  # Γs − sin Γs
    area = 0.5 * re_squared * segment_e * cos_phi + 0.5 * radius**2 * segment_s * cos_psi  # eq 2
    return area, inclination, cos_psi, sin_psi, sin_t, cos_t


def contact_surface(
    penetration: Any, obliquity: Any, radius: Any
) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
    """Presented area A [m²] (eq 2), force inclination φ [rad] (eq 6), cos ψ and sin ψ
    of the incidence ψ = θ − φ (eq 22), and sin θ, cos θ at ``penetration`` P [m],
    ``obliquity`` θ [rad] in [0, π] and ``radius`` Rs [m], one per scene
    (:func:`contact_surface_kernel`: for numbers). What
    ``plateimpact.model.resistance.force_on_contact`` needs."""
    penetration = np.asarray(penetration, dtype=float)
    obliquity = np.asarray(obliquity, dtype=float)
    radius = np.asarray(radius, dtype=float)
    if not penetration.shape == obliquity.shape == radius.shape:
        penetration, obliquity, radius = np.broadcast_arrays(penetration, obliquity, radius)
    phi = force_inclination(penetration, obliquity, radius)
    with np.errstate(divide="ignore", over="ignore"):  # limit_ratio's ±inf clip to ±1
        return _surface(penetration, obliquity, radius, phi)


def contact_surface_kernel(
    penetration: float, obliquity: float, radius: float
) -> tuple[float, float, float, float, float, float]:
    """:func:`contact_surface` of numbers, (A [m²], φ [rad], cos ψ, sin ψ, sin θ, cos θ),
    for a compiled path."""
    phi = force_inclination_kernel(penetration, obliquity, radius)
    return _surface(penetration, obliquity, radius, phi)


def contact_geometry(
    penetration: Any, obliquity: Any, radius: Any
) -> tuple[np.ndarray, np.ndarray]:
    """Presented area A [m²] (eq 2, :func:`presented_area`) and force inclination φ [rad]
    (eq 6, :func:`force_inclination`) at ``penetration`` P [m], ``obliquity`` θ [rad] and
    ``radius`` Rs [m], one per scene (:func:`contact_geometry_kernel`: for numbers).

    Parameters
    ----------
    penetration : P [m]; obliquity : θ [rad], in [0, π]; radius : Rs [m].
    """
    area, phi = contact_surface(penetration, obliquity, radius)[:2]
    return area, phi


def contact_geometry_kernel(
    penetration: float, obliquity: float, radius: float
) -> tuple[float, float]:
    """:func:`contact_geometry` of numbers, (A [m²], φ [rad]), for a compiled path."""
    area, phi = contact_surface_kernel(penetration, obliquity, radius)[:2]
    return area, phi


def branch_surfaces(penetration: Any, obliquity: Any, radius: Any) -> tuple[Any, Any]:
    """P − Rs(1 − sin θ) and P − Rs(1 + sin θ) [m], numbers or arrays: zero on the two
    surfaces where eqs 2–6 change branch.

    On the first, the edge of the forward hemisphere reaches the front plane (Γs leaves 0,
    Γe leaves 2π, φ leaves its clamp at 0); on the second, it leaves the plate at the
    back of the crater (φ reaches θ). There the presented area is continuous but not
    smooth: a circular segment appears with an area that grows as (depth)^{3/2}, and φ
    has a corner. An adaptive integrator steps onto these surfaces rather than across
    them (docs/integrators.md, "branch surfaces"). θ in [0, π].
    """
    lift = radius * sin(obliquity)
    return penetration - (radius - lift), penetration - (radius + lift)


def branch_margins(penetration: Any, obliquity: Any, radius: Any) -> np.ndarray:
    """:func:`branch_surfaces` [m] as rows, shape (2, n), for arrays of n scenes."""
    return np.stack(branch_surfaces(penetration, obliquity, radius))


def contact_lost_margin(penetration: Any, obliquity: Any, radius: Any) -> Any:
    """>= 0 once the sphere moves away from every point of the plate (the forward
    hemisphere and the below-surface cap no longer meet): θ − π/2 >= α1, at
    ``penetration`` P [m], ``obliquity`` θ [rad] and ``radius`` Rs [m]; the margin [m].

    Written without α1's arccos, whose slope is infinite at P = 0, where shallow
    ricochets end: for θ >= π/2 both angles lie in [0, π], where the cosine decreases, so
    the condition is cos α1 = (Rs − P)/Rs >= cos(θ − π/2) = sin θ. The margin is
    min(θ − π/2 [rad], (Rs − P)/Rs − sin θ): zero on the same surface as θ − π/2 − α1
    and of the same sign everywhere, but smooth across it, so its root is found in
    fewer iterations. θ in [0, π].
    """
    return np.minimum(obliquity - HALF_PI, (radius - penetration) / radius - sin(obliquity))


#: The functions of numbers a compiled path compiles (callees before callers).
KERNELS = (
    _clamp,
    embedment_radius_squared,
    entry_edge_angle,
    inclination_bisector,
    in_turnaround_ring,
    ring_inclination,
    eq6_inclination,
    force_inclination_kernel,
    limit_ratio,
    _surface,
    presented_area,
    contact_surface_kernel,
    contact_geometry_kernel,
    branch_surfaces,
    contact_lost_margin,
)
