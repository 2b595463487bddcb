"""The two bodies of an impact: a rigid sphere and a plate (frozen, validated).

All values are SI. Use :mod:`plateimpact.units` to write them in mm, g and degrees.
"""

from __future__ import annotations

import math

import attrs

from . import validation as v


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

    radius: float = v.RADIUS.field()
    mass: float = v.MASS.field()

    @classmethod
    def of_density(cls, radius: float, density: float) -> Sphere:
        """A sphere of ``radius`` [m] made of a material of ``density`` [kg/m³]."""
        v.RADIUS.check("radius", radius)
        v.DENSITY.check("density", density)
        return cls(radius=radius, mass=4.0 / 3.0 * math.pi * radius**3 * density)

    @property
    def density(self) -> float:
        """Mean density [kg/m³]."""
        return self.mass / (4.0 / 3.0 * math.pi * self.radius**3)


@attrs.frozen
class Plate:
    """A plate characterised by the constants of the report's Table 1.

    Parameters
    ----------
    material : str
        A label, e.g. ``"2024-T3"``.
    thickness : float
        T [m], > 0. The report's force law has no back surface: T is kept as a
        description of the plate; it enters the model only through P* and a, b.
    a : float
        Strength term of the Poncelet law (eq 1) [N/m²], > 0.
    b : float
        Inertial term of the Poncelet law (eq 1) [kg/m³], >= 0.
    critical_penetration : float
        P*, the penetration at which the plate fails [m], > 0; ``math.inf`` for a
        plate that never fails.
    failure_angle : float
        α*, where the failure ring sits on the sphere, from the plate normal [rad],
        in (0, π/2).
    """

    material: str = attrs.field(validator=attrs.validators.instance_of(str))
    thickness: float = v.THICKNESS.field()
    a: float = v.STRENGTH_A.field()
    b: float = v.DENSITY_B.field()
    critical_penetration: float = v.CRITICAL_PENETRATION.field()
    failure_angle: float = v.FAILURE_ANGLE.field()
