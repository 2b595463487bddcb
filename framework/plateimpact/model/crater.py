"""Crater sections from trajectories (report eqs 31–39).

The sphere sweeps a tube; the crater is the part of the tube below the front surface,
and its shape is the section in the plane of motion. The report traces the crater floor
as the lower edge of the swept sphere, x = X + Rs sin θ, y = Y − Rs cos θ (eqs 31–32,
X the depth of the centre), and shifts it so that the entry point is the origin
(eqs 37–39).

That curve is the envelope of the swept circle, so it is the floor wherever the envelope
is the boundary. It leaves out two parts of the floor that matter: the front of the
sphere where the trajectory ends (an embedded sphere sits at the bottom of its crater,
so the crater is as deep as the maximum penetration), and normal incidence, where the
envelope is the two vertical walls. plateimpact therefore computes the floor directly:
at each lateral position y, the deepest point of any circle of radius Rs centred on the
trajectory. Where the report's curve is the envelope the two agree (tested); elsewhere
the floor adds the end cap. The section is shifted so that it starts where the floor
crosses the front surface on the entry side: that point is the origin. Given the plate
thickness, a floor below the back surface is a hole and is drawn at depth T (a
perforation's crater is holed where the sphere went through).
"""

from __future__ import annotations

import numpy as np

from .ragged import Ragged
from .results import BatchResult, CraterSection, Trajectory

#: Grid of lateral positions for the floor [points].
DEFAULT_RESOLUTION = 1500
#: Largest spacing of the circles kept from the trajectory, as a fraction of Rs.
CIRCLE_SPACING = 1.0 / 400.0


def _kept_circles(
    centre_lateral: np.ndarray, centre_depth: np.ndarray, radius: float
) -> np.ndarray:
    """Indices of trajectory samples at most CIRCLE_SPACING·Rs apart, with both ends and
    the deepest sample (thinning loses nothing where the sphere barely moves)."""
    step = np.hypot(np.diff(centre_lateral), np.diff(centre_depth))
    travelled = np.concatenate([[0.0], np.cumsum(step)])
    marks = np.arange(0.0, travelled[-1], CIRCLE_SPACING * radius)
    kept = np.searchsorted(travelled, marks)
    extra = [0, travelled.size - 1, int(np.argmax(centre_depth))]
    return np.unique(np.concatenate([kept, extra]))


def crater_floor(
    lateral: np.ndarray,
    centre_lateral: np.ndarray,
    centre_depth: np.ndarray,
    radius: float,
) -> np.ndarray:
    """Depth [m] of the deepest point of any circle (centres given) at each ``lateral`` [m];
    −inf where no circle reaches."""
    floor = np.full(lateral.shape, -np.inf)
    chunk = max(1, 4_000_000 // max(centre_lateral.size, 1))
    for start in range(0, lateral.size, chunk):
        y = lateral[start : start + chunk, np.newaxis]
        half_chord_sq = radius**2 - (y - centre_lateral) ** 2
        below = np.where(
            half_chord_sq >= 0.0, centre_depth + np.sqrt(np.abs(half_chord_sq)), -np.inf
        )
        floor[start : start + chunk] = below.max(axis=1)
    return floor


def crater_section(
    trajectory: Trajectory,
    radius: float,
    *,
    thickness: float = np.inf,
    resolution: int = DEFAULT_RESOLUTION,
) -> CraterSection:
    """The crater section swept by a sphere of ``radius`` [m] along ``trajectory``.

    Works for any trajectory (any integrator, any outcome). With the plate ``thickness``
    [m], a floor below the back surface is a hole and is drawn at depth T. Resolution is
    the number of lateral grid points across the swept width.
    """
    centre_lateral = trajectory.lateral
    centre_depth = trajectory.penetration - radius  # X of eq 33: −Rs at first contact
    kept = _kept_circles(centre_lateral, centre_depth, radius)
    cy, cx = centre_lateral[kept], centre_depth[kept]
    deepest = int(np.argmax(cx))
    low, high = cy.min() - radius, cy.max() + radius
    grid = np.unique(np.concatenate([np.linspace(low, high, resolution), [cy[deepest]]]))
    floor = crater_floor(grid, cy, cx, radius)

    inside = np.flatnonzero(floor > 0.0)
    if inside.size == 0:  # never below the surface: a crater of zero size at the contact
        return CraterSection(np.zeros(1), np.zeros(1), 0.0)
    first, last = inside[0], inside[-1]
    entry = _surface_crossing(grid, floor, first - 1, first) if first > 0 else grid[0]
    exit_ = _surface_crossing(grid, floor, last + 1, last) if last + 1 < grid.size else grid[-1]
    lateral = np.concatenate([[entry], grid[first : last + 1], [exit_]])
    depth = np.concatenate([[0.0], np.clip(floor[first : last + 1], 0.0, thickness), [0.0]])
    return CraterSection(lateral - entry, depth, float(-entry))


def _surface_crossing(grid: np.ndarray, floor: np.ndarray, outside: int, inside: int) -> float:
    """Lateral position where the floor crosses depth 0 between two grid points."""
    if not np.isfinite(floor[outside]):  # the circles end here: the wall is vertical
        return float(grid[inside])
    fraction = floor[inside] / (floor[inside] - floor[outside])
    return float(grid[inside] + fraction * (grid[outside] - grid[inside]))


def crater_sections(result: BatchResult, radius: np.ndarray, thickness: np.ndarray) -> Ragged:
    """The sections of every scene of ``result`` (recorded with its trajectories) for
    sphere radii ``radius`` [m] and plate thicknesses ``thickness`` [m], per scene: a
    ragged array with ``lateral`` and ``depth`` per point and ``impact_point`` per scene
    (as :meth:`BatchResult.crater_of` reads it)."""
    if result.trajectory is None:
        raise ValueError("crater sections need trajectories: run with record_trajectory")
    radius, thickness = np.broadcast_arrays(radius, thickness, np.zeros(len(result)))[:2]
    sections = []
    for i in range(len(result)):
        path = result.trajectory_of(i)
        assert path is not None
        sections.append(crater_section(path, float(radius[i]), thickness=float(thickness[i])))
    return Ragged.from_rows(
        [{"lateral": s.lateral, "depth": s.depth} for s in sections],
        {"impact_point": [s.impact_point for s in sections]},
    )
