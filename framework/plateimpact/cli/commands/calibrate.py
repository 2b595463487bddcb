"""``plateimpact calibrate``: fit a model's plate constants to measured shots, by the
calibration procedure an installed plug-in package provides.

The core knows no procedure: the command hands its parser and arguments to the
``calibrate`` procedure of the registry (``registry.add_procedure``, an object with
``arguments(parser, registry)`` and ``run(args, registry, out) -> int``, written with
:mod:`plateimpact.cli.toolkit`). The built-ins provide the report's (DRI fit, Newton
iteration, the P* search: ``plateimpact_plugins.report``).
"""

from __future__ import annotations

import argparse

from ...registry.plugin_registry import PluginRegistry
from ..writer import Writer

PROCEDURE = "calibrate"


def arguments(p: argparse.ArgumentParser, registry: PluginRegistry) -> None:
    registry.procedure(PROCEDURE).arguments(p, registry)


def run(args: argparse.Namespace, registry: PluginRegistry, out: Writer) -> int:
    """Run ``plateimpact calibrate``: the registered procedure's work."""
    return int(registry.procedure(PROCEDURE).run(args, registry, out))
