"""What ``run`` and ``crater`` share: one scene from the command line, its impact
options declared once (:data:`IMPACT_SPEED`, :data:`IMPACT_OBLIQUITY`)."""

from __future__ import annotations

import argparse

from ..model.scene import IMPACT_OBLIQUITY, IMPACT_SPEED, Scene
from ..registry.plugin_registry import PluginRegistry
from ..run.simulation import Simulation
from .options import add_body_options, add_model_options, bodies, metavar, model_choice, scene_flags


def add_scene_options(
    parser: argparse.ArgumentParser, registry: PluginRegistry, *, required: bool
) -> None:
    """--speed, --obliquity (from their declarations), then the plate, sphere and model
    options."""
    for declared in (IMPACT_SPEED, IMPACT_OBLIQUITY):
        parser.add_argument(
            declared.flag or "", required=required, metavar=metavar(declared),
            help=declared.help(),
        )  # fmt: skip
    add_body_options(parser, registry)
    add_model_options(parser, registry)


def scene_of(args: argparse.Namespace, registry: PluginRegistry) -> tuple[Scene, Simulation, str]:
    """The scene, simulation and plate label that --speed, --obliquity and the plate,
    sphere and model options give."""
    scene_flags(args, "--speed", "--obliquity")
    choice = model_choice(args, registry)
    simulation = choice.simulation()
    sphere, plate, label = bodies(args, choice, simulation.model)
    speed = IMPACT_SPEED.parse(args.speed)
    obliquity = IMPACT_OBLIQUITY.parse(args.obliquity)
    return Scene(sphere, plate, speed, obliquity), simulation, label
