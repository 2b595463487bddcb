"""The ballistic limit at normal incidence with plugging, in closed form: the independent
oracle of the limits finder (tests/test_limits.py), of the uncertainty propagation
(tests/test_uncertainty.py) and of benchmarks/uncertainty.py's convergence."""

from __future__ import annotations

import math

from scipy import integrate

import plateimpact as pi


def swept_volume(plate: pi.Plate, sphere: pi.Sphere) -> float:
    """W = ∫ A_net dP at normal incidence with plugging, by quadrature (docs/calibration.md,
    section 3): A(P) = π (2 Rs p − p²), p = min(P, Rs); beyond P*, the part deeper than
    the failure plane h = Rs cos α* + P* − Rs no longer resists; done at P = h + Rs."""
    rs = sphere.radius
    h = max(rs * math.cos(plate.failure_angle) + plate.critical_penetration - rs, 0.0)

    def area(p: float) -> float:
        p = min(max(p, 0.0), rs)
        return math.pi * (2 * rs * p - p * p)

    def net(p: float) -> float:
        return area(p) - (area(p - h) if p >= plate.critical_penetration else 0.0)

    points = sorted({plate.critical_penetration, rs, h, h + rs})
    return integrate.quad(net, 0.0, h + rs, points=points, epsabs=0, epsrel=1e-12, limit=200)[0]


def ballistic_limit(plate: pi.Plate, sphere: pi.Sphere, rest_speed_fraction: float) -> float:
    """a + b Vr² = (a + b Vs²) R², R² = exp(−2bW/m) (eq 40's form, exact for the model at
    θ = 0). The model ends an impact at rest once V < f Vs (f: rest_speed_fraction), so
    perforation needs Vr >= f Vs: Vs² = a (1 − R²) / (b (R² − f²)), which is the issue's
    V0² = (a/b)(e^{2bW/m} − 1) as f -> 0 (docs/limits.md)."""
    a, b, m, f = plate.a, plate.b, sphere.mass, rest_speed_fraction
    r2 = math.exp(-2 * b * swept_volume(plate, sphere) / m)
    return math.sqrt(a * (1 - r2) / (b * (r2 - f * f)))
