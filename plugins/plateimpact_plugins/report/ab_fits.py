"""a and b fitted to residual speeds: the report's Newton iteration (eqs 44–49) and a
direct least-squares fit."""

from __future__ import annotations

import math

import attrs
import numpy as np
from scipy.optimize import least_squares

from plateimpact import (
    CalibrationError,
    ConvergenceError,
    DriFit,
    Plate,
    Shots,
    Simulation,
    Sphere,
    WorkBoundError,
    calibration,
    fit_dri,
)

from . import fit_views
from .ab_start import (
    check_start,
    energy_balance_start,
    in_model_domain,
    log_domain,
    model_residual_speeds,
)
from .presets import DEFAULT_SPHERE
from .pstar_plan import MAX_FIT_SCENES

MIN_PERFORATIONS = calibration.MIN_PERFORATIONS
fit_model_dri = calibration.fit_model_dri


def normal_shots(shots: Shots) -> Shots:
    """The normal-incidence shots the fits of a and b take (three perforations at least)."""
    return calibration.normal_shots(shots, "a and b")


#: Relative step of a and b for the finite differences of eqs 44–47 (and the direct fit).
DIFFERENCE_STEP = 1e-3
#: The Newton iteration stops when R and V0 of the model match the shots' to this
#: relative difference.
NEWTON_TOLERANCE = 1e-6
#: Newton steps allowed before :class:`ConvergenceError`.
MAX_NEWTON_ITERATIONS = 20
#: Halvings of one Newton step that leaves the model's range of a and b (a, b > 0 and
#: their declared ranges) or the model's perforations.
MAX_HALVINGS = 30
#: The direct fit keeps a and b within this factor of its start.
DIRECT_BOUND_FACTOR = 1e3
#: The direct fit's evaluations of its residuals (and of its Jacobian) at most.
DIRECT_EVALUATIONS = 50
#: Scenes per normal-incidence shot a calibration runs at most, halvings aside: three
#: per shot per Newton step (the start and MAX_NEWTON_ITERATIONS steps), one per
#: residual and two per Jacobian evaluation of the direct fit.
AB_SCENES_PER_SHOT = 3 * (1 + MAX_NEWTON_ITERATIONS) + 3 * DIRECT_EVALUATIONS


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

    __repr__ = fit_views.calibration_repr
    _repr_html_ = fit_views.calibration_html

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

    __repr__ = fit_views.report_repr
    _repr_html_ = fit_views.report_html


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
    normal = normal_shots(shots)
    target = fit_dri(normal.impact_speed, normal.residual_speed)
    speeds = normal.impact_speed
    a, b = start or energy_balance_start(target.R, target.V0, sphere, plate)
    check_start(simulation, a, b)
    scale = np.array([target.R, target.V0])  # relative differences, eqs 48–49 scaled

    def evaluate(a: float, b: float) -> tuple[np.ndarray, list[DriFit] | None]:
        """Residual speeds at (a, b) and its two nudges, and their DRI fits (None if the
        model perforates too few of the speeds for one of them)."""
        constants = [(a, b), (a * (1 + step), b), (a, b * (1 + step))]
        residual = model_residual_speeds(simulation, sphere, plate, speeds, constants)
        found = [fit_model_dri(speeds, r) for r in residual]
        usable = [f for f in found if f is not None]
        return residual, usable if len(usable) == len(found) else None

    residual, fits = evaluate(a, b)
    if fits is None:
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
            if in_model_domain(simulation, *trial):
                trial_residual, trial_fits = evaluate(*trial)
                if trial_fits is not None:
                    break
            correction = correction / 2  # guard the domain: damp the step
        else:
            raise ConvergenceError(
                _not_converged(
                    f"after {iterations} iterations a step halved {MAX_HALVINGS} times still "
                    "left the model's range of a and b or its perforations",
                    fits[0],
                    target,
                )
            )
        (a, b), residual, fits = trial, trial_residual, trial_fits
        assert fits is not None  # the halving loop breaks only on usable fits
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
    max_evaluations: int = DIRECT_EVALUATIONS,
    raise_on_failure: bool = True,
) -> Calibration:
    """a and b by least squares of the model's residual speeds [m/s] to the shots'.

    Over every normal-incidence shot (a shot that did not perforate counts as residual
    speed 0), with :func:`scipy.optimize.least_squares` in the variables ln a, ln b (both
    act as relative changes, so the Jacobian's columns are of one size, and a, b > 0
    holds by construction), bounded within a factor 1000 of ``start`` (default: the
    Newton start) and within the model's ranges of a and b. The Jacobian is a finite
    difference with relative step ``step``, its two extra model runs in one batch.
    Standard errors from s² (JᵀJ)⁻¹, s² the residual variance over the shots that carry
    one (those the data or the model perforates).
    """
    simulation = simulation or Simulation.from_names()
    normal = normal_shots(shots)
    target = fit_dri(normal.impact_speed, normal.residual_speed)
    speeds, measured = normal.impact_speed, normal.residual_speed
    a0, b0 = start or energy_balance_start(target.R, target.V0, sphere, plate)
    check_start(simulation, a0, b0)
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
    low, high = log_domain(simulation)  # a trial outside would be refused by the model
    lower, upper = np.maximum(x0 - bound, low), np.minimum(x0 + bound, high)
    solution = least_squares(
        residuals,
        x0,
        jac=jacobian,
        bounds=(lower, upper),
        method="trf",
        xtol=1e-10,
        ftol=1e-12,
        gtol=1e-12,
        max_nfev=max_evaluations,
    )
    a, b = (float(v) for v in np.exp(solution.x))
    edge = 1e-9 * bound
    at_bound = np.any((solution.x < lower + edge) | (solution.x > upper - edge))
    converged = solution.status > 0 and not at_bound
    if not converged and raise_on_failure:
        reason = (
            "reached a bound (1000x the start, or the model's range of a and b)"
            if at_bound
            else solution.message
        )
        raise ConvergenceError(f"direct fit of a and b did not converge: {reason}")
    J = solution.jac
    carrying = (np.abs(solution.fun) > 0.0) | np.any(J != 0.0, axis=1)
    dof = int(carrying.sum()) - 2
    variance = float(np.sum(solution.fun**2)) / dof if dof > 0 else math.nan
    cov = variance * np.linalg.inv(J.T @ J) * np.outer([a, b], [a, b])
    model = residuals(solution.x) + measured
    model_fit = fit_model_dri(speeds, model)
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
        plate=plate.with_constants(a=a, b=b),
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
    max_scenes: int | None = MAX_FIT_SCENES,
) -> CalibrationReport:
    """The DRI fit of ``shots`` and a, b by both methods (``plate``: T, P*, α*).
    :class:`~plateimpact.base.errors.WorkBoundError` before any scene runs if the fits could
    run more than ``max_scenes`` scenes (AB_SCENES_PER_SHOT per normal-incidence shot;
    None: no bound)."""
    simulation = simulation or Simulation.from_names()
    normal = normal_shots(shots)
    scenes = len(normal) * AB_SCENES_PER_SHOT
    if max_scenes is not None and scenes > max_scenes:
        raise WorkBoundError(
            "max_scenes",
            f"a, b fit: up to {scenes:,} scenes ({len(normal):,} normal-incidence shots, "
            f"{AB_SCENES_PER_SHOT} model runs each at most), more than {max_scenes:,}: fit "
            "fewer shots, or lift the bound (max_scenes=None; --force)",
        )
    return CalibrationReport(
        shots=shots,
        dri=fit_dri(normal.impact_speed, normal.residual_speed),
        newton=newton_fit(shots, plate, sphere=sphere, simulation=simulation),
        direct=direct_fit(shots, plate, sphere=sphere, simulation=simulation),
    )
