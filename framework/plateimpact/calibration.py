"""Calibration of the Poncelet constants a and b from residual speeds at normal incidence.

Three steps, after the report's eqs 40–49 (docs/calibration.md):

* :func:`fit_dri` — the DRI (Recht–Ipson) fit Vr = R (Vs² − V0²)^½ (eq 40) by linear least
  squares of Vr² on Vs² (eq 41, M = R², B = −R² V0²);
* :func:`newton_fit` — the report's iteration: the model is run at normal incidence at the
  shots' impact speeds, its residual speeds fitted the same way, and a, b corrected by 2×2
  Newton steps on the differences in R and V0 (eqs 44–49), from the energy-balance start
  of :func:`energy_balance_start` (our repair of eqs 42–43);
* :func:`direct_fit` — a and b by bounded nonlinear least squares of the model's residual
  speeds to the shots.

P* and α* are fixed beforehand (from craters, as in the report). Every model evaluation
is one batch through :meth:`Simulation.run_batch`.
"""

from __future__ import annotations

import math
from collections.abc import Sequence

import attrs
import numpy as np
from scipy.integrate import quad
from scipy.optimize import least_squares

from .batch import SceneBatch
from .bodies import Plate, Sphere
from .errors import CalibrationError, ConvergenceError, ShotDataError
from .geometry import contact_geometry
from .presets import DEFAULT_SPHERE
from .results import Outcome
from .shots import Shots
from .simulation import Simulation

#: Fewest perforating shots a DRI fit takes: two fix R and V0, a third leaves a residual.
MIN_PERFORATIONS = 3
#: Relative step of a and b for the finite differences of eqs 44–47 (and the direct fit).
DIFFERENCE_STEP = 1e-3
#: The Newton iteration stops when R and V0 of the model match the shots' to this
#: relative difference.
NEWTON_TOLERANCE = 1e-6
#: Newton steps allowed before :class:`ConvergenceError`.
MAX_NEWTON_ITERATIONS = 20
#: Halvings of one Newton step that leaves a, b > 0 or the model's perforations.
MAX_HALVINGS = 30
#: Largest R the start takes: R >= 1 would need b <= 0 (docs/calibration.md).
MAX_START_R = 0.99
#: The direct fit keeps a and b within this factor of its start.
DIRECT_BOUND_FACTOR = 1e3


@attrs.frozen(eq=False)
class DriFit:
    """Least-squares fit of Vr = R (Vs² − V0²)^½ (eq 40) to perforating shots.

    Attributes
    ----------
    R : float
        [-]; the slope of Vr against Vs at high speed.
    V0 : float
        Ballistic limit [m/s].
    R_stderr, V0_stderr : float
        Standard errors [-], [m/s] (0 for exact DRI data).
    covariance : numpy.ndarray
        2×2 covariance of (R [-], V0 [m/s]).
    impact_speed : numpy.ndarray
        Vs of the perforating shots used [m/s].
    residuals : numpy.ndarray
        Measured minus fitted residual speed at those shots [m/s].
    """

    R: float
    V0: float
    R_stderr: float
    V0_stderr: float
    covariance: np.ndarray
    impact_speed: np.ndarray
    residuals: np.ndarray

    @property
    def rms_residual(self) -> float:
        """Root mean square of :attr:`residuals` [m/s]."""
        return float(np.sqrt(np.mean(self.residuals**2)))

    def residual_speed(self, impact_speed: np.ndarray | float) -> np.ndarray:
        """The fitted curve, eq 40 [m/s], 0 below the ballistic limit; ``impact_speed`` [m/s]."""
        vs = np.asarray(impact_speed, dtype=float)
        return self.R * np.sqrt(np.clip(vs**2 - self.V0**2, 0.0, None))


@attrs.frozen(eq=False)
class Calibration:
    """a and b fitted to shots, by the Newton iteration or the direct fit.

    Attributes
    ----------
    method : str
        ``"newton"`` (eqs 44–49) or ``"direct"`` (least squares of residual speeds).
    plate : Plate
        The plate with the fitted a [N/m²] and b [kg/m³].
    a_stderr, b_stderr : float
        Standard errors [N/m²], [kg/m³].
    correlation : float
        Correlation of the errors of a and b [-].
    iterations : int
        Newton steps taken, or Jacobian evaluations of the direct fit.
    converged : bool
        Whether the method met its tolerance (False only with ``raise_on_failure=False``).
    model_fit : DriFit
        The DRI fit of the model's own residual speeds at the shots' impact speeds.
    dri_mismatch : float
        Largest relative difference of the model's R and V0 from the shots' [-].
    rms_residual : float
        Root mean square of model minus measured residual speed over the shots [m/s].
    """

    method: str
    plate: Plate
    a_stderr: float
    b_stderr: float
    correlation: float
    iterations: int
    converged: bool
    model_fit: DriFit
    dri_mismatch: float
    rms_residual: float

    @property
    def a(self) -> float:
        """Fitted strength term a [N/m²]."""
        return self.plate.a

    @property
    def b(self) -> float:
        """Fitted inertial term b [kg/m³]."""
        return self.plate.b


@attrs.frozen(eq=False)
class CalibrationReport:
    """The DRI fit of the shots and both calibrations of a and b."""

    shots: Shots
    dri: DriFit
    newton: Calibration
    direct: Calibration


def fit_dri(impact_speed: np.ndarray, residual_speed: np.ndarray) -> DriFit:
    """DRI fit (eqs 40–41) of the perforating shots among ``impact_speed``,
    ``residual_speed`` [m/s]; shots with residual speed 0 are left out.

    Raises :class:`CalibrationError` with fewer than three perforating shots or when the
    fit has no ballistic limit (V0² <= 0) or R <= 0.
    """
    vs = np.asarray(impact_speed, dtype=float).reshape(-1)
    vr = np.asarray(residual_speed, dtype=float).reshape(-1)
    used = vr > 0.0
    n = int(used.sum())
    if n < MIN_PERFORATIONS:
        raise CalibrationError(
            f"the DRI fit needs at least {MIN_PERFORATIONS} perforating shots, got {n}"
        )
    vs, vr = vs[used], vr[used]
    # Eq 41: Y = M X + B, X = Vs², Y = Vr²; X is scaled so the normal matrix is O(1).
    scale = float(np.mean(vs**2))
    design = np.column_stack([vs**2 / scale, np.ones(n)])
    (slope, intercept), *_ = np.linalg.lstsq(design, vr**2, rcond=None)
    M, B = slope / scale, intercept
    if not M > 0.0:
        raise CalibrationError(
            f"the DRI fit has slope R^2 = {M:.4g} <= 0: residual speeds do not rise with "
            "impact speed"
        )
    if not B < 0.0:
        raise CalibrationError(
            f"the DRI fit gives no ballistic limit (V0^2 = {-B / M:.4g} m^2/s^2 <= 0): "
            "residual speeds do not fall to zero at any impact speed"
        )
    R, V0 = math.sqrt(M), math.sqrt(-B / M)
    sum_squares = float(np.sum((vr**2 - design @ [slope, intercept]) ** 2))
    cov_scaled = sum_squares / (n - 2) * np.linalg.inv(design.T @ design)
    cov_MB = cov_scaled * np.outer([1 / scale, 1.0], [1 / scale, 1.0])
    # Delta method: R = M^½, V0 = (−B/M)^½.
    gradient = np.array([[1 / (2 * R), 0.0], [B / (2 * M**2 * V0), -1 / (2 * M * V0)]])
    cov = gradient @ cov_MB @ gradient.T
    residuals = vr - R * np.sqrt(np.clip(vs**2 - V0**2, 0.0, None))
    return DriFit(R, V0, math.sqrt(cov[0, 0]), math.sqrt(cov[1, 1]), cov, vs.copy(), residuals)


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
    len(impact_speeds)), for each (a [N/m²], b [kg/m³]) in ``constants``; one batch.
    Embedments give 0."""
    speeds = np.asarray(impact_speeds, dtype=float)
    batch = SceneBatch.concat(
        SceneBatch.grid(sphere, attrs.evolve(plate, a=a, b=b), speeds, np.zeros(1))
        for a, b in constants
    )
    result = simulation.run_batch(batch)
    residual = np.where(result.outcome == Outcome.PERFORATION, result.exit_speed, 0.0)
    return residual.reshape(len(constants), speeds.size)


def _normal_shots(shots: Shots) -> Shots:
    """The shots at normal incidence, with at least three perforations (ShotDataError)."""
    normal = shots.normal_incidence()
    perforating = [label for label, p in zip(normal.labels, normal.perforated, strict=True) if p]
    if len(perforating) < MIN_PERFORATIONS:
        listed = f" ({', '.join(perforating)})" if perforating else ""
        raise ShotDataError(
            f"{shots.source}: {len(perforating)} perforating shots at normal incidence{listed}; "
            f"the DRI fit needs at least {MIN_PERFORATIONS}"
        )
    return normal


def _model_fit(speeds: np.ndarray, residual: np.ndarray) -> DriFit | None:
    """The DRI fit of model output, or None where it is unusable (too few perforations)."""
    try:
        return fit_dri(speeds, residual)
    except CalibrationError:
        return None


def newton_fit(
    shots: Shots,
    plate: Plate,
    *,
    sphere: Sphere = DEFAULT_SPHERE,
    simulation: Simulation | None = None,
    start: tuple[float, float] | None = None,
    tolerance: float = NEWTON_TOLERANCE,
    max_iterations: int = MAX_NEWTON_ITERATIONS,
    step: float = DIFFERENCE_STEP,
    raise_on_failure: bool = True,
) -> Calibration:
    """a and b by the report's Newton iteration (eqs 44–49).

    ``plate`` gives T, P* and α* (its a and b are not used); ``start`` is (a [N/m²],
    b [kg/m³]), by default :func:`energy_balance_start`. Each iteration runs the model at
    the normal-incidence shots' impact speeds at (a, b), (a + da, b) and (a, b + db), with
    da = ``step``·a, db = ``step``·b, in one batch, fits eq 40 to each, and solves eqs
    48–49 for the correction. A step that would make a or b <= 0, or after which the
    model perforates at fewer than three of the speeds, is halved (up to 30 times).
    Stops when R and V0 match the shots' within ``tolerance`` (relative); otherwise
    :class:`ConvergenceError` after ``max_iterations`` steps.
    """
    simulation = simulation or Simulation.from_names()
    normal = _normal_shots(shots)
    target = fit_dri(normal.impact_speed, normal.residual_speed)
    speeds = normal.impact_speed
    a, b = start or energy_balance_start(target.R, target.V0, sphere, plate)
    scale = np.array([target.R, target.V0])  # relative differences, eqs 48–49 scaled

    def evaluate(a: float, b: float) -> tuple[np.ndarray, list[DriFit | None]]:
        constants = [(a, b), (a * (1 + step), b), (a, b * (1 + step))]
        residual = model_residual_speeds(simulation, sphere, plate, speeds, constants)
        return residual, [_model_fit(speeds, r) for r in residual]

    residual, fits = evaluate(a, b)
    if any(f is None for f in fits):
        raise CalibrationError(
            f"at the start a = {a:.4g} N/m^2, b = {b:.4g} kg/m^3 the model perforates fewer "
            f"than {MIN_PERFORATIONS} of the shots' impact speeds"
        )
    iterations = 0
    while True:
        values = np.array([[f.R, f.V0] for f in fits]) / scale
        mismatch = np.array([1.0, 1.0]) - values[0]  # (dR, dV0) of eqs 48–49, relative
        # Eqs 44–47: the four partial derivatives, here per relative change of a and b.
        jacobian = np.column_stack([values[1] - values[0], values[2] - values[0]]) / step
        converged = float(np.max(np.abs(mismatch))) < tolerance
        if converged or iterations == max_iterations:
            break
        try:
            correction = np.linalg.solve(jacobian, mismatch)  # (da/a, db/b)
        except np.linalg.LinAlgError:
            raise CalibrationError(
                f"Newton iteration: R and V0 do not depend on a and b at a = {a:.4g} N/m^2, "
                f"b = {b:.4g} kg/m^3"
            ) from None
        for _ in range(MAX_HALVINGS):
            trial = a * (1 + correction[0]), b * (1 + correction[1])
            if min(trial) > 0.0:
                trial_residual, trial_fits = evaluate(*trial)
                if all(f is not None for f in trial_fits):
                    break
            correction = correction / 2  # guard the domain: damp the step
        else:
            raise ConvergenceError(
                _not_converged(
                    f"after {iterations} iterations a step halved {MAX_HALVINGS} times still "
                    "left a, b > 0 or the model's perforations",
                    fits[0],
                    target,
                )
            )
        (a, b), residual, fits = trial, trial_residual, trial_fits
        iterations += 1
    if not converged and raise_on_failure:
        raise ConvergenceError(
            _not_converged(f"no convergence in {max_iterations} iterations", fits[0], target)
        )
    # Uncertainty: the shots' (R, V0) covariance carried through the inverse Jacobian.
    relative_cov = target.covariance / np.outer(scale, scale)
    inverse = np.linalg.inv(jacobian)
    cov = inverse @ relative_cov @ inverse.T * np.outer([a, b], [a, b])
    return _calibration(
        "newton", plate, a, b, cov, iterations, converged, fits[0], target, normal, residual[0]
    )


def _not_converged(reason: str, model: DriFit, target: DriFit) -> str:
    """One line: why the Newton iteration stopped, where it was, and why when known."""
    hint = ""
    if target.R >= 1.0:  # R² = exp(−2bW/m) < 1 for every b > 0 (energy_balance_start)
        hint = "; no a, b > 0 gives R >= 1 (residual speeds rising faster than impact speed)"
    return (
        f"Newton iteration (eqs 44-49): {reason}; model R = {model.R:.5g}, V0 = "
        f"{model.V0:.5g} m/s against the shots' R = {target.R:.5g}, V0 = {target.V0:.5g} m/s"
        f"{hint}"
    )


def direct_fit(
    shots: Shots,
    plate: Plate,
    *,
    sphere: Sphere = DEFAULT_SPHERE,
    simulation: Simulation | None = None,
    start: tuple[float, float] | None = None,
    step: float = DIFFERENCE_STEP,
    max_evaluations: int = 50,
    raise_on_failure: bool = True,
) -> Calibration:
    """a and b by least squares of the model's residual speeds [m/s] to the shots'.

    Over every normal-incidence shot (a shot that did not perforate counts as residual
    speed 0), with :func:`scipy.optimize.least_squares` in the variables ln a, ln b (both
    act as relative changes, so the Jacobian's columns are of one size, and a, b > 0
    holds by construction), bounded within a factor 1000 of ``start`` (default: the
    Newton start). The Jacobian is a finite difference with relative step ``step``, its
    two extra model runs in one batch. Standard errors from s² (JᵀJ)⁻¹, s² the residual
    variance over the shots that carry one (those the data or the model perforates).
    """
    simulation = simulation or Simulation.from_names()
    normal = _normal_shots(shots)
    target = fit_dri(normal.impact_speed, normal.residual_speed)
    speeds, measured = normal.impact_speed, normal.residual_speed
    a0, b0 = start or energy_balance_start(target.R, target.V0, sphere, plate)
    cache: dict[bytes, np.ndarray] = {}

    def residuals(x: np.ndarray) -> np.ndarray:
        key = x.tobytes()
        if key not in cache:
            model = model_residual_speeds(
                simulation, sphere, plate, speeds, [(math.exp(x[0]), math.exp(x[1]))]
            )
            cache[key] = model[0] - measured
        return cache[key]

    def jacobian(x: np.ndarray) -> np.ndarray:
        a, b = math.exp(x[0]), math.exp(x[1])
        constants = [(a * (1 + step), b), (a, b * (1 + step))]
        model = model_residual_speeds(simulation, sphere, plate, speeds, constants)
        base = residuals(x) + measured
        return (model - base).T / math.log1p(step)

    bound = math.log(DIRECT_BOUND_FACTOR)
    x0 = np.array([math.log(a0), math.log(b0)])
    solution = least_squares(
        residuals,
        x0,
        jac=jacobian,
        bounds=(x0 - bound, x0 + bound),
        method="trf",
        xtol=1e-10,
        ftol=1e-12,
        gtol=1e-12,
        max_nfev=max_evaluations,
    )
    a, b = (float(v) for v in np.exp(solution.x))
    at_bound = np.any(np.abs(solution.x - x0) > bound * (1 - 1e-9))
    converged = solution.status > 0 and not at_bound
    if not converged and raise_on_failure:
        reason = "reached the bound 1000x the start" if at_bound else solution.message
        raise ConvergenceError(f"direct fit of a and b did not converge: {reason}")
    J = solution.jac
    carrying = (np.abs(solution.fun) > 0.0) | np.any(J != 0.0, axis=1)
    dof = int(carrying.sum()) - 2
    variance = float(np.sum(solution.fun**2)) / dof if dof > 0 else math.nan
    cov = variance * np.linalg.inv(J.T @ J) * np.outer([a, b], [a, b])
    model = residuals(solution.x) + measured
    model_fit = _model_fit(speeds, model)
    if model_fit is None:
        raise CalibrationError(
            "the direct fit's a, b perforate fewer than three of the shots' impact speeds"
        )
    iterations = int(solution.njev)
    return _calibration(
        "direct", plate, a, b, cov, iterations, converged, model_fit, target, normal, model
    )


def _calibration(
    method: str,
    plate: Plate,
    a: float,
    b: float,
    cov: np.ndarray,
    iterations: int,
    converged: bool,
    model_fit: DriFit,
    target: DriFit,
    normal: Shots,
    model_residual: np.ndarray,
) -> Calibration:
    a_stderr, b_stderr = (math.sqrt(v) if v >= 0 else math.nan for v in np.diag(cov))
    mismatch = max(
        abs(model_fit.R - target.R) / target.R, abs(model_fit.V0 - target.V0) / target.V0
    )
    return Calibration(
        method=method,
        plate=attrs.evolve(plate, a=a, b=b),
        a_stderr=a_stderr,
        b_stderr=b_stderr,
        correlation=float(cov[0, 1] / (a_stderr * b_stderr)) if a_stderr * b_stderr else 0.0,
        iterations=iterations,
        converged=converged,
        model_fit=model_fit,
        dri_mismatch=float(mismatch),
        rms_residual=float(np.sqrt(np.mean((model_residual - normal.residual_speed) ** 2))),
    )


def calibrate(
    shots: Shots,
    plate: Plate,
    *,
    sphere: Sphere = DEFAULT_SPHERE,
    simulation: Simulation | None = None,
) -> CalibrationReport:
    """The DRI fit of ``shots`` and a, b by both methods (``plate``: T, P*, α*)."""
    simulation = simulation or Simulation.from_names()
    normal = _normal_shots(shots)
    options = {"sphere": sphere, "simulation": simulation}
    return CalibrationReport(
        shots=shots,
        dri=fit_dri(normal.impact_speed, normal.residual_speed),
        newton=newton_fit(shots, plate, **options),
        direct=direct_fit(shots, plate, **options),
    )
