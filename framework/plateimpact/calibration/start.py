"""Start values of a and b from the energy balance at normal incidence, and the model's
residual speeds (eqs 42–43, our dimensionally consistent reading: docs/calibration.md)."""

from __future__ import annotations

import math
from collections.abc import Sequence

import numpy as np
from scipy.integrate import quad

from ..base.errors import CalibrationError, ShotDataError
from ..base.parameters import Range
from ..limits.chunked import run_chunked
from ..model.batch import SceneBatch
from ..model.bodies import Plate, Sphere
from ..model.geometry import contact_geometry
from ..model.results import Outcome
from ..run.simulation import Simulation
from ..storage.shots import Shots
from .dri import MIN_PERFORATIONS, DriFit, fit_dri

#: Largest R the start takes: R >= 1 would need b <= 0 (docs/calibration.md).
MAX_START_R = 0.99


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

    h = max(rs * math.cos(plate.failure_angle) + pstar - rs, 0.0)
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


def model_residual_speeds(
    simulation: Simulation,
    sphere: Sphere,
    plate: Plate,
    impact_speeds: np.ndarray,
    constants: Sequence[tuple[float, float]],
) -> np.ndarray:
    """Residual speeds [m/s] of the model at normal incidence, shape (len(constants),
    len(impact_speeds)), at ``impact_speeds`` [m/s], for each (a [N/m²], b [kg/m³]) in
    ``constants``; one batch,
    run RUN_CHUNK scenes at a time. Embedments give 0."""
    speeds = np.asarray(impact_speeds, dtype=float)
    a, b = (np.array([c[k] for c in constants], dtype=float) for k in (0, 1))
    fixed = {name: value for name, value in plate.constants if name not in ("a", "b")}

    def batch_of(index: np.ndarray) -> SceneBatch:
        k, i = np.divmod(index, speeds.size)  # constants-major, as the rows
        return SceneBatch(
            {
                "radius": np.full(index.size, sphere.radius),
                "mass": np.full(index.size, sphere.mass),
                "thickness": np.full(index.size, plate.thickness),
                "impact_speed": speeds[i],
                "impact_obliquity": np.zeros(index.size),
                "a": a[k],
                "b": b[k],
                **{name: np.full(index.size, value) for name, value in fixed.items()},
            }
        )

    residual = np.empty(a.size * speeds.size)
    for where, result in run_chunked(simulation, batch_of, residual.size):
        residual[where] = np.where(result.outcome == Outcome.PERFORATION, result.exit_speed, 0.0)
    return residual.reshape(a.size, speeds.size)


def normal_shots(shots: Shots) -> Shots:
    """The shots at normal incidence that record a residual speed, with at least three
    perforations (ShotDataError)."""
    normal = shots.normal_incidence()
    # A DRI fit reads a residual speed > 0 as a perforation: go/no-go shots (no residual
    # speed) and a rebound's exit speed tell it nothing.
    residual = normal.residual_speed
    normal = normal.take(np.isfinite(residual) & ((residual > 0.0) == normal.perforated))
    # The fits of a and b run one sphere and weigh every shot alike: refuse, not ignore.
    own = np.isfinite(normal.radius) | np.isfinite(normal.mass) | (normal.weight != 1.0)
    if own.any():
        raise ShotDataError(
            f"{normal.labels[int(np.argmax(own))]}: the fits of a and b take one sphere "
            "(--radius, --mass) and equal weights: remove radius_mm, mass_g and weight "
            "from the normal-incidence shots"
        )
    perforating = [label for label, p in zip(normal.labels, normal.perforated, strict=True) if p]
    if len(perforating) < MIN_PERFORATIONS:
        listed = f" ({', '.join(perforating)})" if perforating else ""
        raise ShotDataError(
            f"{shots.source}: {len(perforating)} perforating shots at normal incidence{listed}; "
            f"the DRI fit needs at least {MIN_PERFORATIONS}"
        )
    return normal


def fit_model_dri(speeds: np.ndarray, residual: np.ndarray) -> DriFit | None:
    """The DRI fit of model output, or None where it is unusable (too few perforations)."""
    try:
        return fit_dri(speeds, residual)
    except CalibrationError:
        return None


def _declared_ranges(simulation: Simulation) -> list[tuple[str, Range | None]]:
    declared = simulation.model.plate_constants()
    return [(name, declared[name].range if name in declared else None) for name in ("a", "b")]


def in_model_domain(simulation: Simulation, a: float, b: float) -> bool:
    """Whether a, b > 0 (the fits work in ln a, ln b) lie in the ranges the model
    declares for them, where a trial of either fit may be run."""
    ranges = _declared_ranges(simulation)
    return all(
        value > 0.0 and (allowed is None or bool(allowed.contains(value)))
        for value, (_, allowed) in zip((a, b), ranges, strict=True)
    )


def log_domain(simulation: Simulation) -> tuple[np.ndarray, np.ndarray]:
    """The model's ranges of a and b as bounds on (ln a, ln b)."""
    low, high = np.full(2, -np.inf), np.full(2, np.inf)
    for k, (_, allowed) in enumerate(_declared_ranges(simulation)):
        if allowed is not None:
            with np.errstate(divide="ignore"):  # ln 0 = -inf: no lower bound
                low[k], high[k] = np.log(allowed.low), np.log(allowed.high)
    return low, high


def check_start(simulation: Simulation, a: float, b: float) -> None:
    """CalibrationError unless the start (a, b) lies in the model's domain."""
    if not in_model_domain(simulation, a, b):
        allowed = ", ".join(
            f"{name} {r.describe()}" for name, r in _declared_ranges(simulation) if r is not None
        )
        raise CalibrationError(
            f"the start a = {a:.4g} N/m^2, b = {b:.4g} kg/m^3 from the shots' R and V0 lies "
            f"outside the model's range (a, b > 0; {allowed}): no plate of this model fits them"
        )
