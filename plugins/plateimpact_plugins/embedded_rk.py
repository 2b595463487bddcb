"""Explicit embedded Runge–Kutta pairs with FSAL and dense output, on a batch of scenes."""

from __future__ import annotations

from typing import ClassVar

import attrs
import numpy as np

from plateimpact import (
    MAX_SECONDS,
    MAX_STEPS,
    RTOL,
    DenseOutput,
    Dynamics,
    Integrator,
    PairTableau,
    Parameter,
    PolynomialDenseOutput,
    Range,
    Step,
    StepControl,
    StepperState,
)

#: First step [fraction of Rs/Vs]; the error control takes over from there.
FIRST_STEP = 1e-2

FIXED_STEP = Parameter(
    "fixed_step",
    "a constant step as a fraction of Rs/Vs, without error control (for convergence "
    "studies); none: adaptive",
    range=Range(1e-5, 0.5),  # no finer than the segment method's finest step
    default=None,
    optional=True,
)
BRANCH_LANDING = Parameter(
    "branch_landing",
    "step onto the surfaces where the force stops being smooth instead of across them "
    "(false only to measure what that saves)",
    kind=bool,
    default=True,
)


def _combine(weights: np.ndarray, stages: np.ndarray) -> np.ndarray:
    """Σ_j weights[j] · stages[j], element-wise in a fixed order, skipping zero weights
    (so that a scene's result never depends on which other scenes share its batch)."""
    total = np.zeros_like(stages[0])
    for weight, stage in zip(weights, stages, strict=False):
        if weight != 0.0:
            total += weight * stage
    return total


class RungeKuttaDense(DenseOutput):
    """A pair's dense output, its polynomial built only for the scenes asked for."""

    __slots__ = ("h", "matrix", "stages", "whole", "y0")

    def __init__(self, y0: np.ndarray, h: np.ndarray, stages: np.ndarray, matrix: np.ndarray):
        self.y0, self.h, self.stages, self.matrix = y0, h, stages, matrix
        self.whole: PolynomialDenseOutput | None = None

    def polynomial(self, index: np.ndarray | slice) -> PolynomialDenseOutput:
        """Coefficients c_q = h Σ_j P[j, q] k_j, stage by stage in a fixed order (a scene's
        values never depend on the rest of its batch)."""
        stages = self.stages[:, :, index]
        coefficients = np.zeros((self.matrix.shape[1],) + stages.shape[1:])
        for j in range(stages.shape[0]):
            for q, weight in enumerate(self.matrix[j]):
                if weight != 0.0:
                    coefficients[q] += weight * stages[j]
        return PolynomialDenseOutput(self.y0[:, index], coefficients * self.h[index])

    def __call__(self, sigma: float | np.ndarray) -> np.ndarray:
        if self.whole is None:
            self.whole = self.polynomial(slice(None))
        return self.whole(sigma)

    def take(self, index: np.ndarray) -> PolynomialDenseOutput:
        return self.polynomial(index)


@attrs.frozen
class EmbeddedRungeKutta(Integrator):
    """Abstract: an explicit embedded Runge–Kutta pair with FSAL and dense output.

    A subclass is data: the tableau ``C``, ``A``, ``B``, the error weights ``E`` (over all
    stages, the last being the FSAL stage), the dense-output matrix ``P`` (stage weights
    as polynomials in σ = (t − tn)/h, coefficients of σ, σ², ...), and ``error_order``.
    All scenes advance together, one step each per call; the driver controls the steps
    (``rtol``; docs/integrators.md) and locates events on the dense output.
    """

    C: ClassVar[np.ndarray]
    A: ClassVar[np.ndarray]
    B: ClassVar[np.ndarray]
    E: ClassVar[np.ndarray]
    P: ClassVar[np.ndarray]
    error_order: ClassVar[int]

    rtol: float = RTOL.field()
    max_steps: int = MAX_STEPS.field()
    max_seconds: float | None = MAX_SECONDS.field()
    fixed_step: float | None = FIXED_STEP.field()
    branch_landing: bool = BRANCH_LANDING.field()

    def step_control(self) -> StepControl | None:
        if self.fixed_step is not None:
            return None
        return StepControl(self.rtol, self.error_order, self.branch_landing)

    def compiled_tableau(self) -> PairTableau | None:
        if self.fixed_step is not None:  # fixed steps: the numpy path's convergence studies
            return None
        return PairTableau(self.C, self.A, self.B, self.E, self.P, self.error_order)

    def initial_step(self, dynamics: Dynamics) -> np.ndarray:
        fraction = FIRST_STEP if self.fixed_step is None else self.fixed_step
        return fraction * dynamics.time_scale

    def start(self, dynamics: Dynamics, t: np.ndarray, y: np.ndarray) -> StepperState:
        return {"derivative": dynamics.rates(y)}  # first same as last

    def known_rates(self, state: StepperState) -> np.ndarray:
        return state["derivative"]

    def advance(
        self, dynamics: Dynamics, t: np.ndarray, y: np.ndarray, h: np.ndarray, state: StepperState
    ) -> Step:
        stages = np.empty((len(self.C) + 1, *y.shape))
        stages[0] = state["derivative"]
        for i in range(1, len(self.C)):
            stages[i] = dynamics.rates(y + h * _combine(self.A[i, :i], stages))
        y_new = y + h * _combine(self.B, stages)
        stages[-1] = dynamics.rates(y_new)
        error = h * _combine(self.E, stages)
        dense = RungeKuttaDense(y, h, stages, self.P)
        return Step(y_new, h, error, dense, {"derivative": stages[-1]})
