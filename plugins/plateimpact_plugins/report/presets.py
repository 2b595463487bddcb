"""The plates of the report's Table 1 and its sphere, registered as presets.

Names are ``MATERIAL/THICKNESS_MM``. The 6061-T6 plate is listed as 9.52 mm in Table 1
and 9.53 mm in the figures; its preset is named by the figures and keeps Table 1's
thickness. Table 1 prints it under 2024-T3, but Figures 11–17 and 35 name it 6061-T6
(docs/model.md §9). The report gives no sphere mass: the default sphere is SAE 52100 at
7830 kg/m³, 6.35 mm in diameter (1.0498 g).
"""

from __future__ import annotations

from plateimpact import Plate, PluginRegistry, Sphere, units

deg, mm = units.deg, units.mm

#: Density of the SAE 52100 sphere [kg/m³] (not in the report; a handbook value).
SAE_52100_DENSITY = 7830.0

DEFAULT_SPHERE = Sphere.of_density(radius=0.5 * 6.35 * mm, density=SAE_52100_DENSITY)


def _table_1(material: str, thickness_mm: float, a: float, b: float, pstar_mm: float) -> Plate:
    """A row of Table 1: a [N/m²], b [kg/m³] (eq 1), P* [mm] and α* = 45° (eq 8)."""
    return Plate(
        material,
        thickness_mm * mm,
        a=a,
        b=b,
        critical_penetration=pstar_mm * mm,
        failure_angle=45 * deg,
    )


PLATES: dict[str, Plate] = {
    "2024-T3/1.27": _table_1("2024-T3", 1.27, 0.272e9, 0.129e4, 2.2),
    "2024-T3/3.18": _table_1("2024-T3", 3.18, 0.101e10, 0.126e4, 3.0),
    "2024-T3/6.35": _table_1("2024-T3", 6.35, 0.933e9, 0.974e3, 6.4),
    "6061-T6/9.53": _table_1("6061-T6", 9.52, 0.112e10, 0.580e3, 7.5),
    "SAE1010/1.47": _table_1("SAE1010", 1.47, 0.380e9, 0.148e4, 4.6),
}


def register_presets(registry: PluginRegistry) -> None:
    """Table 1's plates as presets, and the report's sphere as the default sphere."""
    for name, plate in PLATES.items():
        registry.add_plate(name, plate)
    registry.set_sphere(DEFAULT_SPHERE, density=SAE_52100_DENSITY, material="SAE 52100")
