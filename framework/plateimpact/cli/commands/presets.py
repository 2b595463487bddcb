"""``plateimpact presets``: the plate presets and the default sphere, every value in the
unit its declaration gives."""

from __future__ import annotations

import argparse
import json
from typing import Any

from ...base.parameters import Parameter
from ...model.bodies import MASS, RADIUS, THICKNESS
from ...registry.plugin_registry import PluginRegistry
from ..formatting import quantity
from ..writer import Writer

#: The default sphere's density as printed [kg/m^3].
DENSITY = Parameter("density", "density of the default sphere", "kg/m^3")


def arguments(parser: argparse.ArgumentParser, registry: PluginRegistry) -> None:
    parser.add_argument("--json", action="store_true", help="print JSON")


def _user_value(declared: Parameter, value: float) -> float:
    return float(f"{value / declared.scale:.12g}")


def run(args: argparse.Namespace, registry: PluginRegistry, out: Writer) -> int:
    declared = {THICKNESS.name: THICKNESS, **registry.plate_constants}
    rows: dict[str, dict[str, Any]] = {}
    for name, plate in registry.plates.items():
        row: dict[str, Any] = {"material": plate.material}
        for constant, value in [("thickness", plate.thickness), *plate.constants]:
            row[declared[constant].key] = _user_value(declared[constant], value)
        rows[name] = row
    sphere = registry.sphere
    sphere_row = {
        "material": registry.sphere_material,
        RADIUS.key: _user_value(RADIUS, sphere.radius),
        MASS.key: _user_value(MASS, sphere.mass),
        "density_kg_m3": registry.sphere_density,
    }
    if args.json:
        out.say(json.dumps({"plates": rows, "sphere": sphere_row}, indent=2))
        return 0
    keys = list(next(iter(rows.values())))[1:]
    out.say(f"{'plate':14s} {'material':9s} " + " ".join(f"{k:>12s}" for k in keys))
    for name, row in rows.items():
        values = " ".join(f"{row[k]:12.4g}" for k in keys)
        out.say(f"{name:14s} {row['material']:9s} {values}")
    out.say(
        f"\nsphere (default): {registry.sphere_material}, "
        f"radius {quantity(RADIUS, sphere.radius, 4)}, "
        f"mass {quantity(MASS, sphere.mass, 4, 'f')}, density "
        f"{quantity(DENSITY, registry.sphere_density, 0, 'f')}"
    )
    return 0
