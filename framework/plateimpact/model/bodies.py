"""The two bodies of an impact: a rigid sphere and a plate (frozen, validated).

All values are SI. Use :mod:`plateimpact.units` to write them in mm, g and degrees.
"""

from __future__ import annotations

import math
from collections.abc import Iterable, Mapping
from typing import Any

import attrs
import numpy as np

from ..base.errors import ParameterError
from ..base.parameters import Parameter, Range

# The domain (docs/robustness.md, "the input domain"): spheres from a micrometre (fine
# powder) to a metre; densities of solids that stay rigid, from balsa to past osmium,
# the densest element (22.6 g/cm³). The mass range is what those allow; the density of
# a given radius and mass is checked where both are known (check_density).
RADIUS = Parameter("radius", "sphere radius Rs", "m", Range(1e-6, 1.0), "mm", 1e-3, flag="--radius")
DENSITY = Parameter("density", "sphere density", "kg/m^3", Range(100.0, 25_000.0))
MASS = Parameter(
    "mass",
    f"sphere mass m (with Rs, a density {DENSITY.range.describe(unit='kg/m^3')})",
    "kg",
    Range(4e-16, 1.1e5),  # 4/3 π Rs³ ρ at the ends of both ranges, rounded outward
    "g",
    1e-3,
    flag="--mass",
)
# Foils of a micrometre to armour a metre thick.
THICKNESS = Parameter(
    "thickness",
    "plate thickness T (not in the force law: it bounds crater sections)",
    "m",
    Range(1e-6, 1.0),
    "mm",
    1e-3,
    flag="--thickness",
)
#: A density computed from a radius and a mass may round across a bound of DENSITY
#: that the density it was made from met (Sphere.of_density at the bounds).
_DENSITY_ROUNDING = 1e-12


def check_density(radius: Any, mass: Any) -> None:
    """Raise :class:`ParameterError` unless spheres of ``radius`` [m] and ``mass`` [kg],
    each in its range, have a solid's density (:data:`DENSITY`); an array names the
    first bad scene. Named after the mass: any radius alone is a possible sphere."""
    radius, mass = np.asarray(radius, dtype=float), np.asarray(mass, dtype=float)
    density = mass / (4.0 / 3.0 * math.pi * radius**3)
    allowed = DENSITY.range
    low, high = allowed.low * (1 - _DENSITY_ROUNDING), allowed.high * (1 + _DENSITY_ROUNDING)
    bad = ~((density >= low) & (density <= high))
    if not bad.any():
        return
    first = int(np.flatnonzero(bad)[0]) if bad.ndim else 0
    where = f" (scene {first})" if bad.ndim else ""
    r, m, d = (float(np.ravel(x)[first]) for x in (radius, mass, density))
    raise ParameterError(
        MASS.name,
        f"mass {MASS.format(m)} g on radius {RADIUS.format(r)} mm gives a density of "
        f"{DENSITY.format(d)} kg/m^3; the sphere's density must be "
        f"{allowed.describe(unit='kg/m^3')}{where}",
    )


@attrs.frozen
class Sphere:
    """A rigid, non-deforming sphere.

    Parameters
    ----------
    radius : float
        Rs [m], in [1e-6, 1].
    mass : float
        m [kg]; its mean density with ``radius`` in [100, 25000] kg/m³.
    """

    radius: float = RADIUS.field()
    mass: float = MASS.field()

    def __attrs_post_init__(self) -> None:
        check_density(self.radius, self.mass)

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
    if isinstance(value, bool | np.bool_) or not number:
        raise ParameterError(name, f"{name} must be a number, got {value!r}")
    try:
        as_float = float(value)
    except OverflowError:  # an int beyond 1.8e308
        raise ParameterError(name, f"{name} must be a finite number or inf") from None
    if math.isnan(as_float):
        raise ParameterError(name, f"{name} must be a number, got {value!r}")
    return as_float


def _named_constants(
    constants: Mapping[str, float] | Iterable[tuple[str, float]], named: Mapping[str, float]
) -> tuple[tuple[str, float], ...]:
    """(name, SI value) pairs sorted by name, from a mapping or pairs and keywords."""
    try:
        merged = dict(constants)
    except (TypeError, ValueError):
        raise ParameterError(
            "constants",
            f"plate constants must be a mapping or (name, value) pairs, got {constants!r}",
        ) from None
    merged.update(named)
    return tuple(sorted((name, _constant(name, value)) for name, value in merged.items()))


def _material(instance: object, attribute: attrs.Attribute, value: object) -> None:
    if not isinstance(value, str):
        raise ParameterError("material", f"material must be a label (str), got {value!r}")


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
        T [m], in [1e-6, 1]. The report's force law has no back surface: T enters the model only
        through the fitted constants; plateimpact uses it to bound crater sections.
    constants : mapping or pairs, optional
        Constants by name [SI]; keyword arguments add to them (``a=0.272e9``).
    """

    material: str = attrs.field(validator=_material)
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
        self.__attrs_init__(material, thickness, _named_constants(constants, named))

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
