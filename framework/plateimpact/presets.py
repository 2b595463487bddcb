"""The plates of the report's Table 1 and its sphere.

Names are ``MATERIAL/THICKNESS_MM``. The 6061-T6 plate is listed as 9.52 mm in Table 1
and 9.53 mm in the figures; its preset is named by the figures and keeps Table 1's
thickness. Table 1 prints it under 2024-T3, but Figures 11–17 and 35 name it 6061-T6
(model-notes §2). The report gives no sphere mass: the default sphere is SAE 52100 at
7830 kg/m³, 6.35 mm in diameter (1.0498 g).
"""

from __future__ import annotations

from .bodies import Plate, Sphere
from .errors import UnknownNameError
from .units import deg, mm

#: Density of the SAE 52100 sphere [kg/m³] (not in the report; a handbook value).
SAE_52100_DENSITY = 7830.0

DEFAULT_SPHERE = Sphere.of_density(radius=0.5 * 6.35 * mm, density=SAE_52100_DENSITY)

PLATES: dict[str, Plate] = {
    "2024-T3/1.27": Plate("2024-T3", 1.27 * mm, 0.272e9, 0.129e4, 2.2 * mm, 45 * deg),
    "2024-T3/3.18": Plate("2024-T3", 3.18 * mm, 0.101e10, 0.126e4, 3.0 * mm, 45 * deg),
    "2024-T3/6.35": Plate("2024-T3", 6.35 * mm, 0.933e9, 0.974e3, 6.4 * mm, 45 * deg),
    "6061-T6/9.53": Plate("6061-T6", 9.52 * mm, 0.112e10, 0.580e3, 7.5 * mm, 45 * deg),
    "SAE1010/1.47": Plate("SAE1010", 1.47 * mm, 0.380e9, 0.148e4, 4.6 * mm, 45 * deg),
}


def plate(name: str) -> Plate:
    """The preset plate ``name``; UnknownNameError lists the choices."""
    try:
        return PLATES[name]
    except KeyError:
        raise UnknownNameError(
            f"unknown preset {name!r}; choose from: {', '.join(PLATES)}"
        ) from None
