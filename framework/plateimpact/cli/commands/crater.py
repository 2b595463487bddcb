"""``plateimpact crater``: the crater section of one scene (eqs 31-39), as text, CSV and a
figure."""

from __future__ import annotations

import argparse

from ...model.crater import crater_section
from ...model.results import CRATER_FIELDS
from ...model.scene import IMPACT_OBLIQUITY, IMPACT_SPEED
from ...registry.plugin_registry import PluginRegistry
from ...storage.together import write_together
from ..common import add_dpi_option, check_directory, csv_text, figure_output, text_output
from ..formatting import number, quantity, shown
from ..scenes import add_scene_options, scene_of
from ..writer import Writer


def arguments(parser: argparse.ArgumentParser, registry: PluginRegistry) -> None:
    add_scene_options(parser, registry, required=True)
    parser.add_argument("--csv", metavar="FILE", help="write lateral_mm,depth_mm here")
    parser.add_argument("--png", metavar="FILE", help="draw the crater here")
    add_dpi_option(parser)


def run(args: argparse.Namespace, registry: PluginRegistry, out: Writer) -> int:
    check_directory(args.csv, "--csv")
    check_directory(args.png, "--png", "figure")
    scene, simulation, label = scene_of(args, registry)
    result = simulation.run(scene, record_trajectory=True)
    assert result.trajectory is not None
    section = crater_section(
        result.trajectory, scene.sphere.radius, thickness=scene.plate.thickness
    )
    # the crater's length runs along the lateral axis, its depth along the depth axis
    length, depth = CRATER_FIELDS["lateral"], CRATER_FIELDS["depth"]
    impact = (
        f"{quantity(IMPACT_SPEED, scene.impact_speed)} at "
        f"{quantity(IMPACT_OBLIQUITY, scene.impact_obliquity)}"
    )
    out.say(
        f"{shown(label, None)}: {impact} -> {result.outcome.label}; crater "
        f"{quantity(length, section.length, 4)} long, {quantity(depth, section.max_depth, 4)} "
        "deep"
    )
    outputs = []  # the section and its figure land together
    if args.csv is not None:
        lateral, depth = CRATER_FIELDS["lateral"], CRATER_FIELDS["depth"]
        rows = zip(section.lateral / lateral.scale, section.depth / depth.scale, strict=True)
        outputs.append(text_output(args.csv, csv_text([lateral.key, depth.key], rows), "--csv"))
    if args.png is not None:
        from ...figures.crater_sections import plot_crater  # noqa: PLC0415 (matplotlib only when drawing)
        from ...figures.style import FONT, PAGE_WIDTH, SMALL, figure  # noqa: PLC0415

        fig, ax = figure(figsize=(PAGE_WIDTH, 3.2), layout="constrained")
        plot_crater(ax, section, trajectory=result.trajectory, radius=scene.sphere.radius)
        speed = number(IMPACT_SPEED, scene.impact_speed)
        obliquity = number(IMPACT_OBLIQUITY, scene.impact_obliquity)
        ax.set_title(f"{label}, {speed} m/s at {obliquity}°: {result.outcome.label}", fontsize=FONT)
        ax.tick_params(labelsize=SMALL)
        ax.xaxis.label.set_size(FONT)
        ax.yaxis.label.set_size(FONT)
        ax.legend(fontsize=SMALL, loc="upper left", bbox_to_anchor=(1.01, 1.0), frameon=False)
        outputs.append(figure_output(fig, args.png, "--png", args.dpi))
    write_together(outputs)
    return 0
