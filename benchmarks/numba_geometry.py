"""Would compiling the contact geometry pay? The numpy geometry against a numba loop.

The force evaluation is the largest single cost of a sweep, and within it the contact
geometry (eqs 2–6). This times ``plateimpact.model.geometry.contact_geometry`` on 10,000 random
states against the same formulas as one compiled loop per element (numba), after
checking that the two agree. It is an experiment, not a second implementation: the
package does not use it. Measured on the 2-core machine: numpy 1.24 ms, numba 1.11 ms
per 10,000 states — the work is three arccos, a dozen sines, cosines and square roots
per state, which numpy already runs at machine speed, so compiling gains ~10% of the
geometry and numba does not earn a dependency (docs/integrators.md).

Run:  pip install numba && python benchmarks/numba_geometry.py
"""

from __future__ import annotations

import sys
import time

import numpy as np

from plateimpact.model.geometry import HALF_PI, TWO_PI, contact_geometry

try:
    import numba
except ImportError:
    sys.exit("this experiment needs numba: pip install numba")


@numba.njit(cache=True)
def ratio(numerator: float, denominator: float) -> float:
    """numerator/denominator clipped to [−1, 1] with the limits of geometry._limit_ratio."""
    if denominator > 0.0:
        return min(max(numerator / denominator, -1.0), 1.0)
    return 1.0 if numerator > 0.0 else (-1.0 if numerator < 0.0 else 0.0)


@numba.njit(cache=True)
def compiled_geometry(penetration, obliquity, radius):
    area, phi = np.empty(penetration.size), np.empty(penetration.size)
    for i in range(penetration.size):
        p, theta, rs = penetration[i], obliquity[i], radius[i]
        height = rs - p
        re_squared = max(p * (2.0 * rs - p), 0.0)
        ratio_e = ratio(height * np.cos(theta), np.sqrt(re_squared) * np.sin(theta))
        ratio_s = ratio(height, rs * np.sin(theta))
        segment_e = TWO_PI - 2.0 * np.arccos(ratio_e) + 2.0 * ratio_e * np.sqrt(1 - ratio_e**2)
        segment_s = 2.0 * np.arccos(ratio_s) - 2.0 * ratio_s * np.sqrt(1 - ratio_s**2)
        alpha1 = np.arccos(min(max(height / rs, -1.0), 1.0))
        bisector = 0.5 * (alpha1 + theta - HALF_PI)
        inclination = min(max(bisector, 0.0), theta)
        if theta + HALF_PI > TWO_PI - alpha1:  # the turn-around ring
            first = np.sin(0.5 * (alpha1 - theta + HALF_PI))
            second = np.sin(0.5 * (theta + alpha1 - 1.5 * np.pi))
            second_normal = 0.5 * (theta + 2.5 * np.pi - alpha1)
            ring = np.arctan2(
                first * np.sin(bisector) + second * np.sin(second_normal),
                first * np.cos(bisector) + second * np.cos(second_normal),
            )
            inclination = min(ring + TWO_PI if ring < 0.0 else ring, theta)
        phi[i] = inclination
        area[i] = 0.5 * re_squared * segment_e * np.cos(inclination) + 0.5 * rs**2 * segment_s * (
            np.cos(theta - inclination)
        )
    return area, phi


def main() -> None:
    rng = np.random.default_rng(0)
    n = 10_000
    radius = np.full(n, 3.175e-3)
    penetration = rng.uniform(0.0, 2.5, n) * radius
    obliquity = rng.uniform(0.0, np.pi, n)
    area, phi = contact_geometry(penetration, obliquity, radius)
    area_c, phi_c = compiled_geometry(penetration, obliquity, radius)
    assert np.max(np.abs(area_c - area)) <= 1e-12 * area.max() and np.allclose(phi_c, phi)
    for name, function in (("numpy", contact_geometry), ("numba", compiled_geometry)):
        times = []
        for _ in range(5):
            start = time.perf_counter()
            for _ in range(100):
                function(penetration, obliquity, radius)
            times.append((time.perf_counter() - start) / 100)
        print(f"{name}: {min(times) * 1e3:.2f} ms per {n} states")


if __name__ == "__main__":
    main()
