"""``presets`` and ``plugins``: what is installed, with every fact from its declaration,
and the plug-in packages that failed to load."""

from __future__ import annotations

import argparse
import inspect
import json
from typing import Any

from ..base.parameters import Parameter
from ..model.bodies import MASS, RADIUS, THICKNESS
from ..registry.plugin_registry import KINDS, PluginRegistry, default_registry
from .common import say
from .describe import shown


def add_parsers(sub: Any) -> None:
    p = sub.add_parser("presets", help="list the plate presets and the default sphere")
    p.add_argument("--json", action="store_true", help="print JSON")
    p.set_defaults(command_function=presets_command)

    p = sub.add_parser("plugins", help="list the installed plug-ins by kind")
    p.add_argument(
        "--details",
        action="store_true",
        help="each plug-in's settings and plate constants: unit, range, default, flag",
    )
    p.set_defaults(command_function=plugins_command)


def _user_value(declared: Parameter, value: float) -> float:
    return float(f"{value / declared.scale:.12g}")


def presets_command(args: argparse.Namespace) -> None:
    registry = default_registry()
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
        say(json.dumps({"plates": rows, "sphere": sphere_row}, indent=2))
        return
    keys = list(next(iter(rows.values())))[1:]
    say(f"{'plate':14s} {'material':9s} " + " ".join(f"{k:>12s}" for k in keys))
    for name, row in rows.items():
        values = " ".join(f"{row[k]:12.4g}" for k in keys)
        say(f"{name:14s} {row['material']:9s} {values}")
    say(
        f"\nsphere (default): {registry.sphere_material}, radius {sphere.radius * 1e3:.4g} mm, "
        f"mass {sphere.mass * 1e3:.4f} g, density {registry.sphere_density:.0f} kg/m^3"
    )


def _details(registry: PluginRegistry, kind: str, name: str) -> list[str]:
    cls = registry.get(kind, name)
    summary = (inspect.getdoc(cls) or "").split("\n")[0]
    lines = [f"  {shown(name)} (version {shown(cls.version)}, {cls.__module__}): {shown(summary)}"]
    for setting, declared in cls.setting_declarations().items():
        alias = f", or {declared.flag}" if declared.flag else ""
        lines.append(f"      --set {kind}.{setting}=VALUE{alias}: {declared.help()}")
    for declared in cls.plate_constants:
        alias = f", or {declared.flag}" if declared.flag else ""
        lines.append(
            f"      plate constant {declared.name} (plate file key {declared.key}{alias}): "
            f"{declared.help()}"
        )
    return lines


def plugins_command(args: argparse.Namespace) -> None:
    registry = default_registry()
    for kind in KINDS:
        say(f"{kind}: {', '.join(shown(name) for name in registry.names(kind))}")
        if args.details:
            for name in registry.names(kind):
                say("\n".join(_details(registry, kind, name)))
    for package in registry.broken:  # skipped, none of their plug-ins registered
        say(f"broken: {shown(package.describe(), None)}")
        if args.details and package.provides:
            named = ", ".join(f"{kind} {shown(name)}" for kind, name in package.provides)
            say(f"  would provide: {named}")
