"""``plateimpact plugins``: the installed plug-ins by kind, with every fact from their
declarations (``--details``), and the plug-in packages that failed to load."""

from __future__ import annotations

import argparse
import inspect

from ...registry.plugin_registry import KINDS, PluginRegistry
from ..formatting import shown
from ..writer import Writer


def arguments(parser: argparse.ArgumentParser, registry: PluginRegistry) -> None:
    parser.add_argument(
        "--details",
        action="store_true",
        help="each plug-in's settings and plate constants: unit, range, default, flag",
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


def run(args: argparse.Namespace, registry: PluginRegistry, out: Writer) -> int:
    for kind in KINDS:
        out.say(f"{kind}: {', '.join(shown(name) for name in registry.names(kind))}")
        if args.details:
            for name in registry.names(kind):
                out.say("\n".join(_details(registry, kind, name)))
    for package in registry.broken:  # skipped, none of their plug-ins registered
        out.say(f"broken: {shown(package.describe(), None)}")
        if args.details and package.provides:
            named = ", ".join(f"{kind} {shown(name)}" for kind, name in package.provides)
            out.say(f"  would provide: {named}")
    return 0
