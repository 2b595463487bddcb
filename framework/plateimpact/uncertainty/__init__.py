"""Uncertainty: distributions on a scene's inputs, propagated through the model by direct
simulation (Monte Carlo, scrambled Sobol', Latin hypercube), with the probability of each
outcome and its confidence interval (docs/uncertainty.md)."""

from .distributions import Distribution, Fixed, LogNormal, Normal, TruncatedNormal, Uniform
from .inputs import UncertainInput, input_table
from .propagation import Propagation, propagate
from .spec import UncertaintySpec, read_spec

__all__ = [
    "Distribution",
    "Fixed",
    "LogNormal",
    "Normal",
    "Propagation",
    "TruncatedNormal",
    "UncertainInput",
    "UncertaintySpec",
    "Uniform",
    "input_table",
    "propagate",
    "read_spec",
]
