"""The report's plate constants (Table 1): a, b (eq 1), P* and α* (eq 8), declared once.

The built-ins that read them declare these objects; a third-party plug-in that reads one
declares the same object (``from plateimpact_plugins.report import STRENGTH_A``), so that
every plug-in means the same thing by ``a`` or ``critical_penetration``.
"""

from __future__ import annotations

import math

from plateimpact import Parameter, Range

# The ranges (docs/robustness.md, "the input domain"): a is about three times a
# material's flow stress, from soft clays and gels (1e5 N/m², 30 kPa) to past diamond's
# hardness (1e11 N/m², 100 GPa); b is of the order of the plate's density, none denser
# than 1e5 kg/m³; P* is a depth in the plate, from a nanometre (an atomic layer) up,
# inf for a plate that never fails.
STRENGTH_A = Parameter(
    "a",
    "Poncelet strength term a (eq 1)",
    "N/m^2",
    Range(1e5, 1e11),
    flag="--a",
)
DENSITY_B = Parameter(
    "b",
    "Poncelet inertial term b (eq 1)",
    "kg/m^3",
    Range(0.0, 1e5),
    flag="--b",
)
CRITICAL_PENETRATION = Parameter(
    "critical_penetration",
    "critical penetration P*: the plate fails when the penetration reaches it (inf: never)",
    "m",
    Range(1e-9, allow_inf=True),
    "mm",
    1e-3,
    flag="--pstar",
    short="pstar",
)
FAILURE_ANGLE = Parameter(
    "failure_angle",
    "failure angle alpha*: where the failure ring sits on the sphere, from the plate normal",
    "rad",
    Range(0.0, math.pi / 2, True, True),
    "deg",
    math.pi / 180,
    flag="--alpha",
    short="alpha",
)
