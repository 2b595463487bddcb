"""P* (and α*) fitted to oblique shots by maximum likelihood, a and b held fixed
(docs/calibration.md, "P* and α* from oblique shots").

The log-likelihood of the shots (:mod:`.outcome_model`) depends on P* through the
model's boundaries along impact speed at each shot's obliquity, found for many
candidates in the same batches (:mod:`.model_lines`). The search is in x = ln(P*/Rs):

1. a scan of SCAN_POINTS candidates over PSTAR_RANGE, all in one set of batches, which
   brackets the maximum (or shows that the likelihood is flat, or largest at an end);
2. :func:`scipy.optimize.elementwise.find_minimum` (Chandrupatla) from that bracket, to
   X_TOLERANCE in x, every shot set's search advancing in the same batches;
3. the observed information, −d²ℓ/dx², by central differences at step PSTAR_STEP, whose
   inverse square root is the standard error of x (that of P* is P* times it).

With ``fit_alpha`` the maximum is then sought in (x, α*) by Nelder–Mead
(:func:`scipy.optimize.minimize`) from the first fit, and the information matrix comes
from central differences at steps PSTAR_STEP and ALPHA_STEP.
"""

from __future__ import annotations

import math
from collections.abc import Sequence

import attrs
import numpy as np
from scipy.optimize import elementwise, minimize

from plateimpact import ConvergenceError, calibration

Bands = calibration.Bands
Cost = calibration.Cost
LineModel = calibration.LineModel
ProbabilityModel = calibration.ProbabilityModel
ShotLines = calibration.ShotLines
log_likelihood = calibration.log_likelihood
scan_scenes = calibration.scan_scenes
GROUP_SCENES = calibration.GROUP_SCENES

#: The search range of P*, in sphere radii, and the number of candidates its scan runs.
PSTAR_RANGE = (0.1, 4.0)
SCAN_POINTS = 17
#: Chandrupatla's search stops when ln P* is bracketed to this (0.1 % of P*).
X_TOLERANCE = 1e-3
MAX_ITERATIONS = 40
#: Nelder-Mead in (ln P*, α*), whitened (in standard errors), stops when the simplex is
#: this small and its log-likelihoods agree to ALPHA_FIT_F_TOLERANCE; at most
#: ALPHA_FIT_EVALUATIONS.
ALPHA_FIT_X_TOLERANCE = 0.05
ALPHA_FIT_F_TOLERANCE = 1e-2
ALPHA_FIT_EVALUATIONS = 100
#: Steps of the second differences: in ln P* (2 %: a boundary moves by metres per second,
#: far more than the finder's tolerance) and in α* [rad] (2 degrees).
PSTAR_STEP = 0.02
ALPHA_STEP = math.radians(2.0)
#: With α* fitted the information is measured again along its principal directions, a
#: ridge no flatter than this fraction of the steepest curvature (steps at most 100 times
#: the steep direction's).
RIDGE_FLOOR = 1e-4
#: A log-likelihood that varies less than this over the whole range identifies nothing;
#: one that comes within PLATEAU of its maximum at an end of the range bounds P* from one
#: side only (that end is not excluded even at one standard error).
FLAT = 2.0
PLATEAU = 0.5
#: A shot within this many s of a boundary of the fitted model is "near" it.
NEAR = 3.0
#: The failure constants a fit sets.
PSTAR, ALPHA = "critical_penetration", "failure_angle"
_NONE = np.zeros(0)


@attrs.frozen
class PstarEstimate:
    """What one shot set says: P* [m] and its standard error, α* [rad] (its standard
    error NaN unless fitted), their correlation, the log-likelihood at the maximum, σ_r
    [m/s] (NaN without residual speeds), the model's ``bands`` on each line there, and
    ``near``: the shots within NEAR × s of one of them (the bands without their
    residual-speed samples, which the likelihood alone reads). ``identified`` is False when
    the shots do not fix P*; ``reason`` says why."""

    pstar: float
    pstar_stderr: float
    alpha: float
    alpha_stderr: float = math.nan
    correlation: float = math.nan
    log_likelihood: float = math.nan
    residual_sigma: float = math.nan
    bands: tuple[Bands, ...] = ()
    near: int = 0
    identified: bool = True
    reason: str = ""


class Search:
    """The log-likelihood of several shot sets at candidate (P*, α*), memoised (each
    (set, candidate) pair is a pure function of the model) and evaluated together."""

    def __init__(
        self, lines: LineModel, sets: Sequence[ShotLines], model: ProbabilityModel, alpha: float
    ) -> None:
        self.lines, self.sets, self.model, self.alpha = lines, list(sets), model, alpha
        self.radius = float(lines.sphere.radius)
        #: the scan samples of one candidate of each set
        self.scan_scenes = [scan_scenes(shots, lines.resolution) for shots in self.sets]
        self._memo: dict[tuple[int, float, float], tuple[float, float, list[Bands]]] = {}

    @property
    def cost(self) -> Cost:
        return self.lines.cost

    def constants(self, x: float, alpha: float) -> dict[str, float]:
        return {PSTAR: self.radius * math.exp(x), ALPHA: alpha}

    def evaluate(
        self, index: np.ndarray, x: np.ndarray, alpha: np.ndarray | None = None
    ) -> list[tuple[float, float, list[Bands]]]:
        """(log-likelihood, σ_r, bands) of set ``index[i]`` at x[i] = ln(P*/Rs) and
        α*[i] [rad] (default: the plate's)."""
        alpha = np.full(x.shape, self.alpha) if alpha is None else alpha
        keys = [(int(k), float(a), float(b)) for k, a, b in zip(index, x, alpha, strict=True)]
        new = list(dict.fromkeys(key for key in keys if key not in self._memo))
        for group in self._groups(new):
            bands = self.lines.bands(
                [self.sets[k] for k, _, _ in group], [self.constants(a, b) for _, a, b in group]
            )
            for key, found in zip(group, bands, strict=True):
                value, sigma = log_likelihood(self.sets[key[0]], found, self.model)
                # the bands' residual-speed samples served the likelihood; kept, they
                # would grow with sets x candidates x the scan
                self._memo[key] = (value, sigma, [attrs.evolve(b, speeds=_NONE, residual=_NONE)
                                                  for b in found])  # fmt: skip
        return [self._memo[key] for key in keys]

    def _groups(self, keys: list[tuple[int, float, float]]) -> list[list[tuple[int, float, float]]]:
        """``keys`` in consecutive groups of at most GROUP_SCENES scan samples, each group
        one set of batches: what a group holds is bounded, and a request that fits in
        one group (every ordinary one) runs as before."""
        groups: list[list[tuple[int, float, float]]] = []
        total = GROUP_SCENES
        for key in keys:
            n = self.scan_scenes[key[0]]
            if total + n > GROUP_SCENES:
                groups.append([])
                total = 0
            groups[-1].append(key)
            total += n
        return groups

    def value(self, x: np.ndarray, index: np.ndarray) -> np.ndarray:
        """−log-likelihood of sets ``index`` at ``x`` (any shape), for the minimiser."""
        flat_x, flat_k = np.broadcast_arrays(x, index)
        found = self.evaluate(flat_k.reshape(-1), flat_x.reshape(-1))
        return -np.array([value for value, _, _ in found]).reshape(flat_x.shape)

    def near(self, k: int, bands: Sequence[Bands]) -> int:
        """How many shots of set ``k`` lie within NEAR × s of a boundary of ``bands``."""
        shots = self.sets[k]
        count = 0
        for members, found in zip(shots.members, bands, strict=True):
            v = shots.speed[members]
            inner = found.edges[1:-1]
            if inner.size:
                gap = np.min(np.abs(v[:, None] - inner[None, :]), axis=1)
                count += int(np.sum(gap < NEAR * self.model.speed_sigma))
        return count


def fit_sets(search: Search) -> list[PstarEstimate]:
    """P* of every shot set of ``search`` at the plate's α* (see the module's steps);
    a set that does not fix P* gets an unidentified estimate saying why."""
    n = len(search.sets)
    grid = np.linspace(math.log(PSTAR_RANGE[0]), math.log(PSTAR_RANGE[1]), SCAN_POINTS)
    index = np.repeat(np.arange(n), SCAN_POINTS)
    scan = -search.value(np.tile(grid, n), index).reshape(n, SCAN_POINTS)
    out: list[PstarEstimate | None] = [None] * n
    bracketed = []
    for k in range(n):
        best = int(np.argmax(scan[k]))
        if scan[k].max() - scan[k].min() < FLAT:
            out[k] = _unidentified(
                search, f"the likelihood is flat (it varies by {scan[k].max() - scan[k].min():.2g} "
                f"over P* = {_range_mm(search)}): no shot lies near a boundary that P* moves"
            )  # fmt: skip
        elif max(scan[k][0], scan[k][-1]) > scan[k].max() - PLATEAU:
            end = 0 if scan[k][0] > scan[k][-1] else -1
            pstar = search.radius * math.exp(grid[end]) * 1e3
            out[k] = _unidentified(
                search, f"the likelihood does not fall toward the end of the search range, "
                f"P* = {pstar:.3g} mm ({_range_mm(search)}): the shots bound P* from one side "
                "only; shots on both sides of a boundary are needed"
            )  # fmt: skip
        else:
            bracketed.append((k, best))
    if bracketed:
        ks = np.array([k for k, _ in bracketed])
        at = np.array([best for _, best in bracketed])
        result = elementwise.find_minimum(
            search.value,
            (grid[at - 1], grid[at], grid[at + 1]),
            args=(ks,),
            tolerances={"xatol": X_TOLERANCE, "xrtol": 0.0, "fatol": 0.0, "frtol": 0.0},
            maxiter=MAX_ITERATIONS,
        )
        failed = ~np.asarray(result.success)
        if failed.any():
            k = int(ks[np.flatnonzero(failed)[0]])
            raise ConvergenceError(
                f"P* fit did not converge for {_describe(search.sets[k])}: the bracketing "
                f"search stopped with status {int(np.asarray(result.status)[failed][0])} after "
                f"{int(np.asarray(result.nit)[failed][0])} iterations"
            )
        steps = np.array([-PSTAR_STEP, 0.0, PSTAR_STEP])
        x = np.asarray(result.x, dtype=float)
        values = search.evaluate(np.repeat(ks, 3), (x[:, None] + steps).reshape(-1))
        for i, k in enumerate(ks):
            (low, _, _), (centre, sigma, bands), (high, _, _) = values[3 * i : 3 * i + 3]
            information = -(high - 2.0 * centre + low) / PSTAR_STEP**2
            pstar = search.radius * math.exp(x[i])
            if not information > 0.0:
                out[k] = _unidentified(search, "the likelihood is not peaked at its maximum")
                continue
            out[k] = PstarEstimate(
                pstar=pstar,
                pstar_stderr=pstar / math.sqrt(information),
                alpha=search.alpha,
                log_likelihood=centre,
                residual_sigma=sigma,
                bands=tuple(bands),
                near=search.near(k, bands),
            )
    return [e for e in out if e is not None]


def _information(
    search: Search, centre: np.ndarray, basis: np.ndarray
) -> tuple[np.ndarray, list[tuple[float, float, list[Bands]]]]:
    """−d²ℓ/dθ² of shot set 0 at θ = ``centre`` (ln(P*/Rs), α* [rad]) by central
    differences along the columns of ``basis`` (nine candidates, one evaluation), and
    their results (the centre's is the fifth)."""
    offsets = np.array([[i, j] for i in (-1, 0, 1) for j in (-1, 0, 1)], dtype=float)
    points = centre + offsets @ basis.T
    values = search.evaluate(np.zeros(9, dtype=np.int64), points[:, 0], points[:, 1])
    f = np.array([v for v, _, _ in values]).reshape(3, 3)
    cross = (f[2, 2] - f[2, 0] - f[0, 2] + f[0, 0]) / 4
    in_steps = np.array(
        [[f[2, 1] - 2 * f[1, 1] + f[0, 1], cross], [cross, f[1, 2] - 2 * f[1, 1] + f[1, 0]]]
    )
    inverse = np.linalg.inv(basis)
    return -(inverse.T @ in_steps @ inverse), values


def _inside(point: np.ndarray) -> bool:
    low, high = (math.log(r) for r in PSTAR_RANGE)
    return bool(low < point[0] < high and 0.0 < point[1] < math.pi / 2)


def _principal_information(
    search: Search, centre: np.ndarray
) -> tuple[np.ndarray, np.ndarray, list[tuple[float, float, list[Bands]]]]:
    """The information matrix at ``centre``, measured along its own principal directions
    at one standard error each (a first stencil at steps PSTAR_STEP, ALPHA_STEP finds
    them): P* and α* move the failure plane together (eq 8), so the likelihood's ridge is
    narrow and oblique, and axis steps sized for the steep direction cannot see the
    ridge's curvature under the higher-order terms. Returns the information, the basis
    (columns: one standard error along each principal direction; a ridge flatter than
    RIDGE_FLOOR of the steepest is stepped as if it were that steep) and the results."""
    information, values = _information(search, centre, np.diag([PSTAR_STEP, ALPHA_STEP]))
    curvature, directions = np.linalg.eigh(information)
    if not curvature.max() > 0.0:
        return information, np.diag([PSTAR_STEP, ALPHA_STEP]), values
    curvature = np.maximum(curvature, RIDGE_FLOOR * curvature.max())
    basis = directions / np.sqrt(curvature)
    for _ in range(20):  # keep the stencil inside the search range and 0 < α* < 90°
        corners = centre + np.array([[i, j] for i in (-1, 1) for j in (-1, 1)]) @ basis.T
        if all(_inside(c) for c in corners):
            break
        basis = basis / 2
    information, values = _information(search, centre, basis)
    return information, basis, values


def fit_with_alpha(search: Search, start: PstarEstimate) -> tuple[PstarEstimate, bool]:
    """P* and α* of shot set 0 by Nelder–Mead from ``start`` (P* at the plate's α*), in
    coordinates whitened by the information matrix there (unit steps are one standard
    error along each principal direction, so the oblique ridge is round); returns the
    estimate and whether Nelder–Mead converged inside the bounds."""
    centre = np.array([math.log(start.pstar / search.radius), search.alpha])
    _, basis, _ = _principal_information(search, centre)
    zero = np.zeros(1, dtype=np.int64)

    def negative(z: np.ndarray) -> float:
        point = centre + basis @ z
        if not _inside(point):
            return math.inf
        ((value, _, _),) = search.evaluate(zero, point[:1], point[1:])
        return -value

    result = minimize(
        negative,
        np.zeros(2),
        method="Nelder-Mead",
        options={
            "initial_simplex": np.array([[0.0, 0.0], [1.0, 0.0], [0.0, 1.0]]),
            "xatol": ALPHA_FIT_X_TOLERANCE,
            "fatol": ALPHA_FIT_F_TOLERANCE,
            "maxfev": ALPHA_FIT_EVALUATIONS,
        },
    )
    best = centre + basis @ result.x
    information, _, values = _principal_information(search, best)
    if not np.all(np.linalg.eigvalsh(information) > 0.0):
        return _unidentified(
            search,
            "the likelihood is not peaked in (P*, alpha*): the shots fix the failure plane "
            "(eq 8: h = Rs cos alpha* + P* - Rs) but not P* and alpha* apart",
        ), False
    cov = np.linalg.inv(information)
    x, alpha = (float(v) for v in best)
    pstar = search.radius * math.exp(x)
    centre_value, sigma, bands = values[4]
    estimate = PstarEstimate(
        pstar=pstar,
        pstar_stderr=pstar * math.sqrt(cov[0, 0]),
        alpha=alpha,
        alpha_stderr=math.sqrt(cov[1, 1]),
        correlation=float(cov[0, 1] / math.sqrt(cov[0, 0] * cov[1, 1])),
        log_likelihood=centre_value,
        residual_sigma=sigma,
        bands=tuple(bands),
        near=search.near(0, bands),
    )
    return estimate, bool(result.success) and _inside(best)


def _unidentified(search: Search, reason: str) -> PstarEstimate:
    return PstarEstimate(math.nan, math.nan, search.alpha, identified=False, reason=reason)


def _range_mm(search: Search) -> str:
    low, high = (search.radius * r * 1e3 for r in PSTAR_RANGE)
    return f"{low:.3g}-{high:.3g} mm"


def _describe(shots: ShotLines) -> str:
    degrees = ", ".join(f"{math.degrees(o):g}" for o in np.unique(shots.obliquity))
    return f"the {shots.speed.size} shots at {degrees} deg"
