"""Contact geometry of a sphere in a plate (report eqs 2–6, reused as eqs 9–13).

Conventions (docs/model.md): the plate's front surface is the plane z = 0 with z growing
into the plate; the penetration P [m] is the depth of the sphere's deepest point, so the
centre is at depth P − Rs; the obliquity θ [rad] is the angle of the velocity from the
inward normal (0 normal incidence, π/2 grazing, π straight back out).

The **contact surface** is the part of the sphere that is below the front surface and on
the forward hemisphere. Its projection on the contact plane is the presented area A; the
force acts along the contact-plane normal, at the inclination φ from the plate normal.

Every function takes arrays (one value per scene) and broadcasts. All arccos/arcsin
arguments are clamped to [−1, 1]: they leave it in legitimate states (docs/model.md §2,
"Clamps"), and the clamped values are the report's own special cases ("then Γe = 2π",
"then Γs = 0").
For the plugging relief (eqs 9–13), call the same functions with P − h in place of P.
"""

from __future__ import annotations

import numpy as np

HALF_PI = 0.5 * np.pi
TWO_PI = 2.0 * np.pi


def _clamp(value: np.ndarray, low: float | np.ndarray, high: float | np.ndarray) -> np.ndarray:
    """np.clip at a third of its call overhead (the geometry runs six times a step)."""
    return np.minimum(np.maximum(value, low), high)


def embedment_radius_squared(penetration: np.ndarray, radius: np.ndarray) -> np.ndarray:
    """Re², the squared radius of the circle cut by the front plane (eq 3) [m²].

    Zero when the sphere does not reach the plane (P <= 0) or has passed it (P >= 2 Rs).
    """
    return np.maximum(penetration * (2.0 * radius - penetration), 0.0)


def entry_edge_angle(penetration: np.ndarray, radius: np.ndarray) -> np.ndarray:
    """α1 [rad]: angle, at the centre and from the inward normal, of the point where the
    front surface cuts the sphere in the plane of motion. 0 at first contact, π/2 when
    the centre reaches the surface, π once the sphere is wholly below it."""
    return np.arccos(_clamp((radius - penetration) / radius, -1.0, 1.0))


def force_inclination(
    penetration: np.ndarray, obliquity: np.ndarray, radius: np.ndarray
) -> np.ndarray:
    """φ [rad], the angle of the contact-plane normal (the force) from the plate normal;
    ``penetration`` P [m], ``obliquity`` θ [rad] and ``radius`` Rs [m], one per scene.

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
    bisector = 0.5 * (alpha1 + obliquity - HALF_PI)  # eq 6
    phi = _clamp(bisector, 0.0, obliquity)
    ring = obliquity + HALF_PI > TWO_PI - alpha1
    if ring.any():
        # Chord lengths (/2Rs) and normal directions of the two arcs of the ring regime:
        # (θ − π/2, α1) and (2π − α1, θ + π/2).
        th, a1, b1 = obliquity[ring], alpha1[ring], bisector[ring]
        first = np.sin(0.5 * (a1 - th + HALF_PI))
        second = np.sin(0.5 * (th + a1 - 1.5 * np.pi))
        second_normal = 0.5 * (th + 2.5 * np.pi - a1)
        ring_phi = np.arctan2(
            first * np.sin(b1) + second * np.sin(second_normal),
            first * np.cos(b1) + second * np.cos(second_normal),
        )
        # φ <= θ holds analytically (the longer arc lies behind the path); the clip only
        # removes arctan2 round-off near θ = π, where the two chords nearly cancel.
        phi[ring] = np.minimum(np.where(ring_phi < 0.0, ring_phi + TWO_PI, ring_phi), th)
    return phi


def _limit_ratio(numerator: np.ndarray, denominator: np.ndarray) -> np.ndarray:
    """numerator/denominator clipped to [−1, 1], for denominator >= 0, with the limit at
    denominator = 0: ±1 by the sign of the numerator, and 0 for 0/0 (the limit θ → 0 at
    P = Rs)."""
    with np.errstate(divide="ignore", invalid="ignore", over="ignore"):
        ratio = numerator / denominator  # ±inf (zero or subnormal denominator) clips to ±1
    np.maximum(ratio, -1.0, out=ratio)
    np.minimum(ratio, 1.0, out=ratio)
    undefined = np.isnan(ratio)  # 0/0 only: a zero denominator otherwise gives ±inf
    if undefined.any():
        ratio[undefined] = 0.0
    return ratio


def contact_geometry(
    penetration: np.ndarray, obliquity: np.ndarray, radius: np.ndarray
) -> tuple[np.ndarray, np.ndarray]:
    """Presented area A [m²] (eq 2) and force inclination φ [rad] (eq 6) at
    ``penetration`` P [m], ``obliquity`` θ [rad] and ``radius`` Rs [m], one per scene.

    A is the projection of the contact surface on the contact plane. By the divergence
    theorem it equals the projections of the two flat faces that close the contact
    surface: the forward segment of the front-plane disc (radius Re, central angle Γe,
    eq 4) and the below-surface segment of the great disc normal to the velocity (radius
    Rs, central angle Γs, eq 5).

    Parameters
    ----------
    penetration : P [m]; obliquity : θ [rad], in [0, π]; radius : Rs [m].
    """
    penetration = np.asarray(penetration, dtype=float)
    obliquity = np.asarray(obliquity, dtype=float)
    radius = np.asarray(radius, dtype=float)
    if not penetration.shape == obliquity.shape == radius.shape:
        penetration, obliquity, radius = np.broadcast_arrays(penetration, obliquity, radius)

    centre_height = radius - penetration  # height of the centre above the front plane
    re_squared = embedment_radius_squared(penetration, radius)
    sin_t, cos_t = np.sin(obliquity), np.cos(obliquity)
    # eq 4, (Rs − P)/(Re tan θ) written with sin and cos so that θ = 0 is a limit.
    ratio_e = _limit_ratio(centre_height * cos_t, np.sqrt(re_squared) * sin_t)
    ratio_s = _limit_ratio(centre_height, radius * sin_t)  # eq 5
    # Γ − sin Γ for Γe = 2π − 2 arccos r and Γs = 2 arccos r, with sin(2 arccos r) written
    # as 2 r √(1 − r²): the same values without two more sine evaluations.
    chord_e = 2.0 * ratio_e * np.sqrt(1.0 - ratio_e * ratio_e)
    chord_s = 2.0 * ratio_s * np.sqrt(1.0 - ratio_s * ratio_s)
    segment_e = TWO_PI - 2.0 * np.arccos(ratio_e) + chord_e  # Γe − sin Γe
    segment_s = 2.0 * np.arccos(ratio_s) - chord_s  # Γs − sin Γs

    phi = force_inclination(penetration, obliquity, radius)
    area = 0.5 * re_squared * segment_e * np.cos(phi) + 0.5 * radius**2 * segment_s * np.cos(
        obliquity - phi
    )  # eq 2
    return area, phi


def branch_margins(
    penetration: np.ndarray, obliquity: np.ndarray, radius: np.ndarray
) -> np.ndarray:
    """P − Rs(1 − sin θ) and P − Rs(1 + sin θ) [m], shape (2, n): zero on the two surfaces
    where eqs 2–6 change branch.

    On the first, the edge of the forward hemisphere reaches the front plane (Γs leaves 0,
    Γe leaves 2π, φ leaves its clamp at 0); on the second, it leaves the plate at the
    back of the crater (φ reaches θ). There the presented area is continuous but not
    smooth: a circular segment appears with an area that grows as (depth)^{3/2}, and φ
    has a corner. An adaptive integrator steps onto these surfaces rather than across
    them (docs/integrators.md, "branch surfaces"). θ in [0, π].
    """
    lift = radius * np.sin(obliquity)
    return np.stack([penetration - (radius - lift), penetration - (radius + lift)])


def contact_lost_margin(
    penetration: np.ndarray, obliquity: np.ndarray, radius: np.ndarray
) -> np.ndarray:
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
    return np.minimum(obliquity - HALF_PI, (radius - penetration) / radius - np.sin(obliquity))
