"""Dense output: the state inside a step, as a function of σ = (t − tn)/h in [0, 1].

A stepper returns one with every step; the driver samples it to find events and to
record trajectories, and refines event times on it. Two generic ones are here: a
polynomial in σ (Runge–Kutta dense output) and the cubic Hermite interpolant, which any
one-step method can use from the states and derivatives at the ends of its step.
"""

from __future__ import annotations

from abc import ABC, abstractmethod

import numpy as np


class DenseOutput(ABC):
    """The states of m scenes inside their current steps."""

    @abstractmethod
    def __call__(self, sigma: float | np.ndarray) -> np.ndarray:
        """States at the fractions ``sigma`` of the step (one for all, or one per scene),
        shape (d, m)."""

    @abstractmethod
    def take(self, index: np.ndarray) -> DenseOutput:
        """The dense output of the scenes at ``index`` (repeats allowed)."""


class PolynomialDenseOutput(DenseOutput):
    """y(σ) = y0 + σ(c_0 + σ(c_1 + ...)): ``y0`` (d, m) and ``coefficients`` (Q, d, m),
    evaluated by Horner's rule."""

    __slots__ = ("coefficients", "y0")

    def __init__(self, y0: np.ndarray, coefficients: np.ndarray) -> None:
        self.y0 = y0
        self.coefficients = coefficients

    def __call__(self, sigma: float | np.ndarray) -> np.ndarray:
        total = self.coefficients[-1] * sigma
        for coefficient in self.coefficients[-2::-1]:
            total = (total + coefficient) * sigma
        return self.y0 + total

    def take(self, index: np.ndarray) -> PolynomialDenseOutput:
        return PolynomialDenseOutput(self.y0[:, index], self.coefficients[:, :, index])


def hermite(
    y0: np.ndarray, y1: np.ndarray, f0: np.ndarray, f1: np.ndarray, h: np.ndarray
) -> PolynomialDenseOutput:
    """The cubic Hermite interpolant of a step of length ``h`` [s] from ``y0`` to ``y1``
    with derivatives ``f0``, ``f1`` at its ends: third order, for any one-step method."""
    d0, d1, dy = h * f0, h * f1, y1 - y0
    return PolynomialDenseOutput(y0, np.stack([d0, 3.0 * dy - 2.0 * d0 - d1, d0 + d1 - 2.0 * dy]))
