"""The DRI (Recht–Ipson) fit of residual speeds, eqs 40–41."""

from __future__ import annotations

import math

import attrs
import numpy as np

from ..base import display
from ..base.errors import CalibrationError, ParameterError
from ..storage.shots import Shots

#: Fewest perforating shots a DRI fit takes: two fix R and V0, a third leaves a residual.
MIN_PERFORATIONS = 3
#: Smallest spread of Vs² among them, relative to the largest, that determines a slope
#: (below it the normal equations are singular to rounding).
SPEED_SPREAD = 1e-6


@attrs.frozen(eq=False, repr=False)
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
        """Root mean square of ``residuals`` [m/s]."""
        return float(np.sqrt(np.mean(self.residuals**2)))

    def __repr__(self) -> str:
        speed, quantity = display.SPEED, display.quantity
        parts = [
            f"R {self.R:.5g} +/- {self.R_stderr:.2g}",
            f"V0 {display.cell(speed, self.V0, 5)} +/- {quantity(speed, self.V0_stderr, 2)}",
            f"{self.impact_speed.size:,} perforating shots",
            f"rms residual {quantity(speed, self.rms_residual, 3)}",
        ]
        return display.short_repr("DriFit", parts)

    def _repr_html_(self) -> str:
        speed, cell = display.SPEED, display.cell
        rows = [
            ["R", f"{self.R:.5g}", f"{self.R_stderr:.2g}"],
            [display.heading("V0", speed), cell(speed, self.V0, 5), cell(speed, self.V0_stderr, 2)],
        ]
        fields = [
            ("perforating shots", f"{self.impact_speed.size:,}"),
            (display.heading("rms residual", speed), cell(speed, self.rms_residual, 3)),
        ]
        table = display.html_table(["", "estimate", "standard error"], rows)
        title = "DriFit: Vr = R (Vs^2 - V0^2)^(1/2) (eq 40)"
        return display.html_block(title, table, display.html_fields(fields))

    def residual_speed(self, impact_speed: np.ndarray | float) -> np.ndarray:
        """The fitted curve, eq 40 [m/s], 0 below the ballistic limit; ``impact_speed`` [m/s]."""
        vs = np.asarray(impact_speed, dtype=float)
        return self.R * np.sqrt(np.clip(vs**2 - self.V0**2, 0.0, None))


def fit_dri(impact_speed: np.ndarray | Shots, residual_speed: np.ndarray | None = None) -> DriFit:
    """DRI fit (eqs 40–41) of the perforating shots among ``impact_speed``,
    ``residual_speed`` [m/s]; shots with residual speed 0 are left out. Or
    ``impact_speed`` is :class:`~plateimpact.Shots` alone, at one obliquity: the residual
    speeds of those that perforated (a ricochet's exit speed is not one), the same fit.

    Raises :class:`CalibrationError` with fewer than three perforating shots or when the
    fit has no ballistic limit (V0² <= 0) or R <= 0.
    """
    if isinstance(impact_speed, Shots):
        if residual_speed is not None:
            raise ParameterError(
                "residual_speed", "give Shots alone, or impact and residual speeds as arrays"
            )
        shots = impact_speed.at_one_obliquity("a DRI fit")
        impact_speed = shots.impact_speed
        residual_speed = np.where(shots.perforated, shots.residual_speed, 0.0)
    elif residual_speed is None:
        raise ParameterError("residual_speed", "residual_speed is needed with impact speeds")
    vs = np.asarray(impact_speed, dtype=float).reshape(-1)
    vr = np.asarray(residual_speed, dtype=float).reshape(-1)
    used = vr > 0.0
    n = int(used.sum())
    if n < MIN_PERFORATIONS:
        raise CalibrationError(
            f"the DRI fit needs at least {MIN_PERFORATIONS} perforating shots, got {n}"
        )
    vs, vr = vs[used], vr[used]
    # Eq 41 fits a line through (Vs², Vr²): shots at (nearly) one speed fix no slope.
    spread = float(np.ptp(vs**2)) / float(np.max(vs**2))
    if not spread > SPEED_SPREAD:
        raise CalibrationError(
            f"the DRI fit needs perforating shots at different impact speeds; these span "
            f"{float(np.ptp(vs)):.3g} m/s around {float(np.mean(vs)):.4g} m/s"
        )
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
