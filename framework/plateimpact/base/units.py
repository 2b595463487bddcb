"""Unit factors between the user's edge and the SI units used inside.

Inside plateimpact everything is SI (m, kg, s, N, rad). Users speak mm, m/s, g and
degrees; multiply by these factors on the way in and divide on the way out::

    from plateimpact.units import mm, deg
    Sphere.of_density(radius=3.175 * mm, density=7830.0)
"""

from __future__ import annotations

import math

mm = 1.0e-3
"""One millimetre [m]."""
g = 1.0e-3
"""One gram [kg]."""
deg = math.pi / 180.0
"""One degree [rad]."""
us = 1.0e-6
"""One microsecond [s] (contact times as the command line prints them)."""
