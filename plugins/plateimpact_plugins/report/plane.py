"""The failure plane of the report's plugging (eq 8): where the plate separates."""

from __future__ import annotations

import numpy as np


def failure_plane_depth(
    radius: np.ndarray | float, failure_angle: np.ndarray | float, onset: np.ndarray | float
) -> np.ndarray:
    """Depth h [m] of the failure plane below the front surface: the depth of the ring at
    α* [rad] on a sphere of ``radius`` Rs [m] when the penetration is ``onset`` [m].

    h = Rs cos α* + P − Rs (eq 8 with P the onset penetration, P* for plugging); when
    h < 0 the ring is still above the front surface at onset and the whole contact region
    separates: h = 0. The one expression of eq 8: the plane-separation models and the
    calibration's swept volume both call it.
    """
    return np.maximum(radius * np.cos(failure_angle) + onset - radius, 0.0)
