"""Would compiling the contact geometry pay? The numpy geometry against a numba loop.

The force evaluation is the largest single cost of a sweep, and within it the contact
geometry (eqs 2–6). This times ``plateimpact.model.geometry.contact_geometry`` on 10,000 random
states against numba's compilation of the package's own kernel of numbers,
``contact_geometry_kernel`` (the same formulas, geometry.KERNELS), in one loop per
element, after checking that the two agree. Measured on the 2-core machine before the
kernels were shared: numpy 1.24 ms, numba 1.11 ms per 10,000 states — the work is three
arccos, a dozen sines, cosines and square roots per state, which numpy already runs at
machine speed, so compiling the geometry alone gains ~10% (docs/integrators.md).

Run:  pip install plateimpact[fast] && python benchmarks/numba_geometry.py
"""

from __future__ import annotations

import sys
import time

import numpy as np

from plateimpact.model import geometry
from plateimpact.model.geometry import contact_geometry, contact_geometry_kernel

try:
    import numba
except ImportError:
    sys.exit("this experiment needs numba: pip install plateimpact[fast]")

for kernel in geometry.KERNELS:  # so that compiled callers find their callees
    numba.extending.register_jitable(kernel)


@numba.njit(error_model="numpy")
def compiled_geometry(penetration, obliquity, radius):
    area, phi = np.empty(penetration.size), np.empty(penetration.size)
    for i in range(penetration.size):
        area[i], phi[i] = contact_geometry_kernel(penetration[i], obliquity[i], radius[i])
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
