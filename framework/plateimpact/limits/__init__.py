"""Limits and outcome maps: every outcome band of a plate, its boundaries located to a
tolerance, for any model (docs/limits.md).

>>> limits = along_speed(simulation, sphere, plate, np.radians([0, 45, 60]))
>>> limits.lines[1].ballistic_limit, limits.lines[1].bands
>>> archive_limits("runs.h5", "plugging", limits)  # stored beside the studies
>>> compare_limits(read_limits("runs.h5", "plugging"), read_limits("runs.h5", "hinge"))
"""

from __future__ import annotations

from .archived import archive_limits, read_limits, stored_limits
from .bracketing import Located, locate
from .compare import BoundaryShift, LimitsComparison, LineComparison, compare_limits
from .lines import OBLIQUITY, SPEED, Band, Boundary, LimitLine
from .maps import MAP_OBLIQUITIES, MAP_SPEED_SAMPLES, OutcomeMap, outcome_map, outcome_maps
from .plate_limits import (
    MAX_SCAN_SCENES,
    OBLIQUITY_RANGE,
    OBLIQUITY_RESOLUTION,
    OBLIQUITY_TOLERANCE,
    SPEED_RANGE,
    SPEED_RESOLUTION,
    SPEED_TOLERANCE,
    Limits,
    along_obliquity,
    along_speed,
)
from .regimes import REGIMES, Regime, regime_codes

__all__ = [
    "MAP_OBLIQUITIES",
    "MAP_SPEED_SAMPLES",
    "MAX_SCAN_SCENES",
    "OBLIQUITY",
    "OBLIQUITY_RANGE",
    "OBLIQUITY_RESOLUTION",
    "OBLIQUITY_TOLERANCE",
    "REGIMES",
    "SPEED",
    "SPEED_RANGE",
    "SPEED_RESOLUTION",
    "SPEED_TOLERANCE",
    "Band",
    "Boundary",
    "BoundaryShift",
    "LimitLine",
    "Limits",
    "LimitsComparison",
    "LineComparison",
    "Located",
    "OutcomeMap",
    "Regime",
    "along_obliquity",
    "along_speed",
    "archive_limits",
    "compare_limits",
    "locate",
    "outcome_map",
    "outcome_maps",
    "read_limits",
    "regime_codes",
    "stored_limits",
]
