"""``plateimpact map``: the outcome map of the (speed, obliquity) plane for one to four
plates, or the limit curves of several."""

from __future__ import annotations

import argparse
import copy

from ... import limits as lim
from ...model.scene import IMPACT_OBLIQUITY
from ...registry.plugin_registry import PluginRegistry
from ...run.progress import reporting_scenes
from ..common import UsageError, add_dpi_option, check_directory, save_figure_atomically
from ..formatting import shown
from ..limit_options import (
    add_archive_options,
    finite_number,
    step,
    store,
    values,
    writable_archive,
)
from ..options import add_body_options, add_model_options, bodies, model_choice, typed
from ..writer import Writer


def arguments(p: argparse.ArgumentParser, registry: PluginRegistry) -> None:
    p.add_argument(
        "--speeds", default="50:2000:200", help="START:STOP:N [m/s] (default 50:2000:200)"
    )
    p.add_argument(
        "--obliquities", default="0:85:86", help="START:STOP:N or a list [deg] (default 0:85:86)"
    )
    p.add_argument("--tolerance", default="0.01", help="boundaries to this [m/s] (default 0.01)")
    p.add_argument(
        "--kind",
        choices=("outcomes", "limits"),
        default="outcomes",
        help="outcomes: the plane coloured by outcome (one panel per --preset); limits: "
        "ballistic and ricochet limits against obliquity for every --preset",
    )
    p.add_argument("--png", metavar="FILE", required=True, help="draw here")
    add_dpi_option(p)
    add_archive_options(p, "map_PRESET_FAILURE")
    add_body_options(p, registry, many_presets=True)
    add_model_options(p, registry)


def run(args: argparse.Namespace, registry: PluginRegistry, out: Writer) -> int:
    check_directory(args.png, "--png", "figure")
    archive = writable_archive(args)
    typed(args).update({"speeds": "--speeds", "impact_speed": "--speeds",
                        "obliquities": "--obliquities", "impact_obliquity": "--obliquities",
                        "tolerance": "--tolerance", "speed_samples": "--speeds"})  # fmt: skip
    parts = args.speeds.split(":")
    if len(parts) != 3:
        raise UsageError(f"--speeds must be START:STOP:N in m/s, got {args.speeds!r}")
    extent = (finite_number(parts[0], "--speeds"), finite_number(parts[1], "--speeds"))
    try:
        samples = int(parts[2])
    except ValueError:
        raise UsageError(f"--speeds: N must be an integer >= 2, got {parts[2]!r}") from None
    rows = values(args.obliquities, "--obliquities", "deg") * IMPACT_OBLIQUITY.scale
    tolerance = step(args.tolerance, "--tolerance")
    presets_given = args.preset or [None]
    if args.kind == "outcomes" and len(presets_given) > 4:
        raise UsageError("--preset: an outcome map draws at most 4 plates (one panel each)")
    choice = model_choice(args, registry)
    simulation = choice.simulation()
    plates = []
    for preset in presets_given:
        given = copy.copy(args)
        given.preset = preset
        plates.append(bodies(given, choice, simulation.model))
    spheres = {sphere for sphere, _, _ in plates}  # one, from --radius and --mass
    with reporting_scenes("map"):
        found = lim.outcome_maps(simulation, spheres.pop(), [plate for _, plate, _ in plates],
                                 extent, samples, rows, tolerance=tolerance)  # fmt: skip
    maps = [(label, one) for (_, _, label), one in zip(plates, found, strict=True)]
    shape, counted = found[0].shape, found[0].limits
    out.say(
        f"{', '.join(shown(label, None) for label, _ in maps)}: {len(maps)} map(s) of {shape[0]} x "
        f"{shape[1]}, {counted.scenes:,} scenes in {counted.seconds:.1f} s"
    )
    from ...figures.limits_and_maps import plot_limit_curves, plot_outcome_map  # noqa: PLC0415

    draw = plot_outcome_map if args.kind == "outcomes" else plot_limit_curves
    save_figure_atomically(draw(maps), args.png, dpi=args.dpi)
    out.say(f"figure:  {args.png}")
    failure = simulation.model.failure.name
    for label, drawn in maps:
        name = f"map_{label}_{failure}"
        if args.name:
            name = args.name if len(maps) == 1 else f"{args.name}_{label}"
        store(archive, name, drawn, out)
    return 0
