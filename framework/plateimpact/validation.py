"""Range checks shared by the configuration classes and the batch constructor.

A :class:`Range` knows the parameter's display unit, so that a message shows the value
the user typed (``radius must be > 0 mm, got -1 mm``) even though the value is checked
in SI.
"""

from __future__ import annotations

import math
from typing import Any

import attrs
import numpy as np

from .errors import ParameterError


@attrs.frozen
class Range:
    """An allowed interval for one parameter.

    Parameters
    ----------
    low, high : float
        Bounds [SI units]; ``math.inf`` for none.
    low_open, high_open : bool
        Whether the bound itself is excluded.
    unit : str
        Display unit of the message (``mm``, ``deg``, ``m/s``).
    scale : float
        SI value of one display unit (1e-3 for mm).
    allow_inf : bool
        Whether +inf is an acceptable value (an "extremely large" P*).
    """

    low: float = -math.inf
    high: float = math.inf
    low_open: bool = False
    high_open: bool = False
    unit: str = ""
    scale: float = 1.0
    allow_inf: bool = False

    def describe(self) -> str:
        """The allowed interval in display units, e.g. ``in [0, 90) deg`` or ``> 0 mm``."""
        low, high = self.low / self.scale, self.high / self.scale
        unit = f" {self.unit}" if self.unit else ""
        if math.isinf(high):
            return f"{'>' if self.low_open else '>='} {_fmt(low)}{unit}"
        if math.isinf(low):
            return f"{'<' if self.high_open else '<='} {_fmt(high)}{unit}"
        left = "(" if self.low_open else "["
        right = ")" if self.high_open else "]"
        return f"in {left}{_fmt(low)}, {_fmt(high)}{right}{unit}"

    def contains(self, value: Any) -> np.ndarray:
        """Element-wise membership (NaN is never a member)."""
        value = np.asarray(value, dtype=float)
        ok = (value > self.low) if self.low_open else (value >= self.low)
        ok &= (value < self.high) if self.high_open else (value <= self.high)
        if not self.allow_inf:
            ok &= np.isfinite(value)
        return ok & ~np.isnan(value)

    def check(self, name: str, value: Any) -> None:
        """Raise :class:`ParameterError` naming ``name`` unless every value is allowed."""
        ok = self.contains(value)
        if not np.all(ok):
            bad = np.asarray(value, dtype=float)[~ok] if np.ndim(value) else value
            first = float(np.ravel(bad)[0])
            unit = f" {self.unit}" if self.unit else ""
            where = ""
            if np.ndim(value):
                where = f" (scene {int(np.flatnonzero(~ok)[0])})"
            raise ParameterError(
                name,
                f"{name} must be {self.describe()}, got {_fmt(first / self.scale)}{unit}{where}",
            )

    def validator(self):
        """An attrs validator using this range, naming the attribute."""

        def _validate(instance: Any, attribute: attrs.Attribute, value: float) -> None:
            self.check(attribute.name, value)

        return _validate

    def field(self, **kwargs: Any) -> Any:
        """An attrs field holding a float in this range (other types: ParameterError)."""
        return attrs.field(converter=FLOAT, validator=self.validator(), **kwargs)


def _to_float(value: Any, field: attrs.Attribute) -> float:
    if isinstance(value, bool) or not isinstance(value, int | float | np.floating | np.integer):
        raise ParameterError(field.name, f"{field.name} must be a number, got {value!r}")
    return float(value)


FLOAT = attrs.Converter(_to_float, takes_field=True)


def _fmt(x: float) -> str:
    if math.isnan(x):
        return "nan"
    if math.isinf(x):
        return "inf" if x > 0 else "-inf"
    return f"{x:.6g}"


# The ranges of the model's parameters, shared by Sphere/Plate/Scene and SceneBatch.
RADIUS = Range(0.0, low_open=True, unit="mm", scale=1e-3)
MASS = Range(0.0, low_open=True, unit="g", scale=1e-3)
DENSITY = Range(0.0, low_open=True, unit="kg/m^3")
THICKNESS = Range(0.0, low_open=True, unit="mm", scale=1e-3)
STRENGTH_A = Range(0.0, low_open=True, unit="N/m^2")
DENSITY_B = Range(0.0, unit="kg/m^3")
CRITICAL_PENETRATION = Range(0.0, low_open=True, unit="mm", scale=1e-3, allow_inf=True)
FAILURE_ANGLE = Range(0.0, math.pi / 2, True, True, unit="deg", scale=math.pi / 180)
IMPACT_SPEED = Range(0.0, low_open=True, unit="m/s")
IMPACT_OBLIQUITY = Range(0.0, math.pi / 2, high_open=True, unit="deg", scale=math.pi / 180)
