"""Start values of a and b from the energy balance at normal incidence (eqs 42–43, our
dimensionally consistent reading: docs/calibration.md), and the ranges a and b keep."""

from __future__ import annotations

import math

import numpy as np
from scipy.integrate import quad

from plateimpact import CalibrationError, Plate, Simulation, Sphere, calibration, contact_geometry

from .plane import failure_plane_depth

#: Largest R the start takes: R >= 1 would need b <= 0 (docs/calibration.md).
MAX_START_R = 0.99
#: The plate constants the fits of eqs 40–49 find.
AB = ("a", "b")


def swept_volume(sphere: Sphere, plate: Plate) -> float:
    """W [m³]: the integral of the net presented area over the penetration at normal
    incidence, from first contact to perforation, with plugging at P* (eq 8).

    At θ = 0 the presented area is A(P) = π (2 Rs p − p²), p = min(P, Rs) (eqs 2–3); after
    failure the part deeper than h = Rs cos α* + P* − Rs no longer resists (eqs 9–15), and
    perforation is complete at P = h + Rs.
    """
    rs, pstar = sphere.radius, plate.critical_penetration
    if not math.isfinite(pstar):
        raise CalibrationError("a plate that never fails (P* = inf) cannot be perforated")

    def area(p: float) -> float:  # A at θ = 0 from the core geometry: eqs 2–6 exist once
        return float(contact_geometry(np.array([p]), np.zeros(1), np.array([rs]))[0][0])

    def area_integral(lo: float, hi: float) -> float:  # ∫ A dP [m³]; A has a kink at Rs
        if hi <= lo:
            return 0.0
        points = [rs] if lo < rs < hi else None
        return quad(area, lo, hi, points=points, epsabs=0.0, epsrel=1e-13, limit=200)[0]

    h = float(failure_plane_depth(rs, plate.failure_angle, pstar))
    end = max(h + rs, pstar)
    # The intact area up to perforation, less the relieved area beyond the plane after P*.
    return area_integral(0.0, end) - area_integral(max(pstar - h, 0.0), end - h)


def energy_balance_start(
    R: float, V0: float, sphere: Sphere, plate: Plate, *, volume: float | None = None
) -> tuple[float, float]:
    """Start values (a [N/m²], b [kg/m³]) of the Newton iteration from the shots' R [-]
    and V0 [m/s] (our dimensionally consistent eqs 42–43, docs/calibration.md).

    At normal incidence m V dV = −A (a + b V²) dP integrates to
    a + b Vr² = (a + b Vs²) exp(−2 b W / m), W the swept volume [m³]: eq 40 exactly, with
    R² = exp(−2 b W / m) and V0² = (a / b)(1/R² − 1). Inverted:
    b = m ln(1/R) / W and a = b R² V0² / (1 − R²) (→ m V0² / 2W, the energy balance, as
    b → 0). ``volume`` replaces W (e.g. π Rs² T, the thickness reading of eq 42).
    R is capped at 0.99 so the start stays in a, b > 0.
    """
    volume = swept_volume(sphere, plate) if volume is None else volume
    R = min(R, MAX_START_R)
    b = sphere.mass * math.log(1.0 / R) / volume
    return b * R**2 * V0**2 / (1.0 - R**2), b


def in_model_domain(simulation: Simulation, a: float, b: float) -> bool:
    """Whether a, b > 0 (the fits work in ln a, ln b) lie in the ranges the model
    declares for them, where a trial of either fit may be run."""
    return calibration.in_model_domain(simulation, {"a": a, "b": b})


def log_domain(simulation: Simulation) -> tuple[np.ndarray, np.ndarray]:
    """The model's ranges of a and b as bounds on (ln a, ln b)."""
    return calibration.log_domain(simulation, AB)


def check_start(simulation: Simulation, a: float, b: float) -> None:
    """CalibrationError unless the start (a, b) lies in the model's domain."""
    if not in_model_domain(simulation, a, b):
        allowed = ", ".join(
            f"{name} {r.describe()}"
            for name, r in calibration.declared_ranges(simulation, AB)
            if r is not None
        )
        raise CalibrationError(
            f"the start a = {a:.4g} N/m^2, b = {b:.4g} kg/m^3 from the shots' R and V0 lies "
            f"outside the model's range (a, b > 0; {allowed}): no plate of this model fits them"
        )


def model_residual_speeds(
    simulation: Simulation,
    sphere: Sphere,
    plate: Plate,
    impact_speeds: np.ndarray,
    constants: list[tuple[float, float]],
) -> np.ndarray:
    """Residual speeds [m/s] at normal incidence for each (a [N/m²], b [kg/m³]) of
    ``constants``, shape (len(constants), len(impact_speeds)) (the core's
    :func:`plateimpact.calibration.model_residual_speeds`)."""
    candidates = [dict(zip(AB, c, strict=True)) for c in constants]
    return calibration.model_residual_speeds(simulation, sphere, plate, impact_speeds, candidates)
