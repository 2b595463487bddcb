"""Validators for integrator settings shared by the built-in integrators."""

from __future__ import annotations

import attrs

from plateimpact import ParameterError


def check_rtol(instance: object, attribute: attrs.Attribute, value: float) -> None:
    """rtol in [1e-14, 1e-2]."""
    if not (isinstance(value, int | float) and 1e-14 <= value <= 1e-2):
        raise ParameterError("rtol", f"rtol must be in [1e-14, 1e-2], got {value!r}")


def check_max_steps(instance: object, attribute: attrs.Attribute, value: int) -> None:
    """A positive integer number of steps."""
    if not (isinstance(value, int) and value > 0):
        raise ParameterError("max_steps", f"max_steps must be an integer > 0, got {value!r}")
