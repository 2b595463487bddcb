"""The maximum of the go/no-go likelihood (plateimpact.v50.likelihood): Newton's method
with a backtracking line search on the convex −log L(β0, β1), z = β0 + β1 x (x the
speeds centred and scaled), started from the best flat curve, with scipy's trust-region
solver as the fallback.

Why not the trust-region solver alone: near the maximum it judges a step by the
improvement in −log L it brings, and a step that should take the gradient from 10⁻⁷ to
10⁻¹⁴ improves −log L by about 10⁻¹⁵ of itself, which is rounding. It then refused the
step and stopped short of the gradient tolerance, and whether it did depended on the
order in which the shots were summed (docs/experiment.md, "V50 statistics"). Newton's
method here asks for no improvement it cannot see: a step whose predicted gain is
below the rounding of −log L is taken whole, as the last one, and the fit is judged by
its gradient alone.
"""

from __future__ import annotations

from collections.abc import Callable

import numpy as np
from scipy import optimize

from ..base.errors import V50Error
from .likelihood import GoNoGo, LikelihoodMaximum, Link

#: A maximum is accepted where |d(−log L)/dβ| <= this × the total weight (the rounds);
#: Newton's method takes at most this many steps (a convex problem takes fewer than 20,
#: and it goes on to rounding), the fallback as many more.
GRADIENT_TOLERANCE, MAX_ITERATIONS = 1e-8, 200
#: A Newton step whose predicted gain in −log L is below this share of −log L (a few
#: units of rounding) is the last: no line search can tell a better point from it.
ROUNDING_GAIN = 64 * float(np.finfo(float).eps)
#: The line search: sufficient decrease (Armijo) and the shortest step tried.
ARMIJO, SHORTEST_STEP = 1e-4, 1e-12
#: Eigenvalues of the Hessian below this share of the largest are raised to it, so that
#: a Hessian made singular by underflowing curvatures still gives a descent direction.
EIGENVALUE_FLOOR = 1e-12

Problem = Callable[[np.ndarray], tuple[float, np.ndarray, np.ndarray]]


def _problem(shots: GoNoGo, link: Link) -> Problem:
    """−log L, its gradient and Hessian at β."""
    design = np.column_stack([np.ones_like(shots.x), shots.x])

    def at(beta: np.ndarray) -> tuple[float, np.ndarray, np.ndarray]:
        eta = design @ beta
        first, second = shots.eta_derivatives(eta, link)
        value = shots.negative_log_likelihood(eta, link)
        return value, design.T @ first, (design.T * second) @ design

    return at


def flat_start(shots: GoNoGo, link: Link) -> np.ndarray:
    """The best flat curve, P = the share perforated (slope 0): finite −log L, and the
    maximum of the likelihood where the slope is held at 0."""
    share = float(shots.weight[shots.sign > 0].sum() / shots.weight.sum())
    return np.array([link.quantile(share), 0.0])


def _newton_step(gradient: np.ndarray, hessian: np.ndarray) -> np.ndarray:
    """−H⁻¹ g, with H's eigenvalues floored (a descent direction even if H is singular)."""
    values, vectors = np.linalg.eigh(hessian)
    top = max(float(values.max()), float(np.finfo(float).tiny))
    floored = np.maximum(values, EIGENVALUE_FLOOR * top)
    return np.asarray(-(vectors @ ((vectors.T @ gradient) / floored)))


def newton(problem: Problem, start: np.ndarray) -> tuple[np.ndarray, int]:
    """Newton's method with backtracking from ``start``: the last point and the steps
    taken. It goes on to the rounding of −log L, not to a tolerance, so that where it
    stops does not depend on the path (nor on the order of the sums) beyond rounding:
    it stops after a step whose predicted gain is rounding (taken whole unless that makes
    −log L worse by more than rounding), or when the line search finds no decrease."""
    beta = start
    value, gradient, hessian = problem(beta)
    for iteration in range(MAX_ITERATIONS):
        step = _newton_step(gradient, hessian)
        gain = -float(gradient @ step)  # the predicted decrease is gain/2 (gain >= 0)
        rounding = ROUNDING_GAIN * abs(value)
        if gain <= rounding:  # the last step: rounding would judge it, so take it whole
            last = problem(beta + step)[0]
            return (beta + step if last <= value + rounding else beta), iteration + 1
        length = 1.0
        while True:
            trial = beta + length * step
            trial_value, trial_gradient, trial_hessian = problem(trial)
            if np.isfinite(trial_value) and trial_value <= value - ARMIJO * length * gain:
                break
            length *= 0.5
            if length < SHORTEST_STEP:  # no decrease rounding can see: the smaller gradient
                full = problem(beta + step)[1]
                better = np.abs(full).max() < np.abs(gradient).max()
                return (beta + step if better else beta), iteration + 1
        beta, value, gradient, hessian = trial, trial_value, trial_gradient, trial_hessian
    return beta, MAX_ITERATIONS


def _trust_region(problem: Problem, start: np.ndarray, tolerance: float) -> tuple[np.ndarray, int]:
    """scipy's trust-region solver (exact gradient and Hessian) from ``start``."""
    found = optimize.minimize(
        lambda b: problem(b)[0], start, jac=lambda b: problem(b)[1],
        hess=lambda b: problem(b)[2], method="trust-exact",
        options={"gtol": tolerance, "maxiter": MAX_ITERATIONS},
    )  # fmt: skip
    return np.asarray(found.x, dtype=float), int(found.nit)


def maximum(shots: GoNoGo, link: Link, label: str) -> LikelihoodMaximum:
    """The maximum of the likelihood (β0, β1): Newton from the best flat curve, then the
    trust-region solver from where Newton stopped if that is not a maximum. V50Error
    (one line) if neither reaches a gradient within the tolerance, which the shots
    check_shots lets through do not make happen (their likelihood has a maximum)."""
    problem = _problem(shots, link)
    tolerance = GRADIENT_TOLERANCE * float(shots.weight.sum())

    def converged(beta: np.ndarray) -> bool:
        if not np.all(np.isfinite(beta)):
            return False
        value, gradient, _ = problem(beta)
        return bool(np.isfinite(value) and np.abs(gradient).max() <= tolerance)

    start = flat_start(shots, link)
    beta, steps = newton(problem, start)
    if not converged(beta):
        restart = beta if np.all(np.isfinite(beta)) else start
        beta, more = _trust_region(problem, restart, tolerance)
        steps += more
        if not converged(beta):
            raise V50Error(
                f"{label}: the {link.name} fit did not converge: neither Newton's method nor "
                f"the trust-region solver reached a gradient within {tolerance:.3g} "
                f"after {steps} steps"
            )
    value = problem(beta)[0]
    return LikelihoodMaximum(float(beta[0]), float(beta[1]), value, steps)


__all__ = ["GRADIENT_TOLERANCE", "MAX_ITERATIONS", "flat_start", "maximum", "newton"]
