"""The two bodies of an impact: a rigid sphere and a plate (frozen, validated).

All values are SI. Use :mod:`plateimpact.units` to write them in mm, g and degrees.
"""

from __future__ import annotations

import math
from collections.abc import Iterable, Mapping
from typing import Any

import attrs
import numpy as np

from .errors import ParameterError
from .parameters import Parameter, Range

RADIUS = Parameter(
    "radius", "sphere radius Rs", "m", Range(0.0, low_open=True), "mm", 1e-3, flag="--radius"
)
MASS = Parameter("mass", "sphere mass m", "kg", Range(0.0, low_open=True), "g", 1e-3, flag="--mass")
DENSITY = Parameter("density", "sphere density", "kg/m^3", Range(0.0, low_open=True))
THICKNESS = Parameter(
    "thickness",
    "plate thickness T (not in the force law: it bounds crater sections)",
    "m",
    Range(0.0, low_open=True),
    "mm",
    1e-3,
    flag="--thickness",
)


@attrs.frozen
class Sphere:
    """A rigid, non-deforming sphere.

    Parameters
    ----------
    radius : float
        Rs [m], > 0.
    mass : float
        m [kg], > 0.
    """

    radius: float = RADIUS.field()
    mass: float = MASS.field()

    @classmethod
    def of_density(cls, radius: float, density: float) -> Sphere:
        """A sphere of ``radius`` [m] made of a material of ``density`` [kg/m³]."""
        RADIUS.validate(radius)
        DENSITY.validate(density)
        return cls(radius=radius, mass=4.0 / 3.0 * math.pi * radius**3 * density)

    @property
    def density(self) -> float:
        """Mean density [kg/m³]."""
        return self.mass / (4.0 / 3.0 * math.pi * self.radius**3)


def _constant(name: str, value: Any) -> float:
    """A plate constant: a real number, not NaN (+inf allowed: P* of a plate that never
    fails). Its range is checked by the plug-in that declares it, when a model uses it."""
    if not isinstance(name, str) or not name.isidentifier():
        raise ParameterError(str(name), f"plate constant names are identifiers, got {name!r}")
    number = isinstance(value, int | float | np.integer | np.floating)
    if isinstance(value, bool | np.bool_) or not number or math.isnan(value):
        raise ParameterError(name, f"{name} must be a number, got {value!r}")
    return float(value)


@attrs.frozen(init=False)
class Plate:
    """A plate: a material label, a thickness, and named constants.

    The constants are whatever the model's plug-ins declare: the report's Table 1 gives
    ``a`` [N/m²] and ``b`` [kg/m³] (Poncelet, eq 1), ``critical_penetration`` P* [m] and
    ``failure_angle`` α* [rad] (plugging, eq 8); a third-party law may add its own. Read
    them as attributes (``plate.a``). Each constant's unit and range belong to the plug-in
    that declares it and are checked when a model uses the plate.

    Parameters
    ----------
    material : str
        A label, e.g. ``"2024-T3"``.
    thickness : float
        T [m], > 0. The report's force law has no back surface: T enters the model only
        through the fitted constants; plateimpact uses it to bound crater sections.
    constants : mapping or pairs, optional
        Constants by name [SI]; keyword arguments add to them (``a=0.272e9``).
    """

    material: str = attrs.field(validator=attrs.validators.instance_of(str))
    thickness: float = THICKNESS.field()
    #: (name, SI value) pairs, sorted by name.
    constants: tuple[tuple[str, float], ...] = attrs.field(default=())

    def __init__(
        self,
        material: str,
        thickness: float,
        constants: Mapping[str, float] | Iterable[tuple[str, float]] = (),
        **named: float,
    ) -> None:
        merged = dict(constants)
        merged.update(named)
        pairs = tuple(sorted((name, _constant(name, value)) for name, value in merged.items()))
        self.__attrs_init__(material, thickness, pairs)

    def __getattr__(self, name: str) -> float:
        if name.startswith("_") or name == "constants":
            raise AttributeError(name)
        for key, value in self.constants:
            if key == name:
                return value
        known = ", ".join(key for key, _ in self.constants) or "none"
        raise AttributeError(f"plate {self.material!r} has no constant {name!r} (it has {known})")

    def constant_values(self) -> dict[str, float]:
        """The constants as a dict [SI]."""
        return dict(self.constants)

    def with_constants(self, **changes: float) -> Plate:
        """The same plate with some constants changed or added [SI]."""
        return Plate(self.material, self.thickness, {**self.constant_values(), **changes})
