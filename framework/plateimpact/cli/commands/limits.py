"""``plateimpact limits``: outcome bands, ballistic and ricochet limits along impact speed
or obliquity, in the units of the axis's declaration."""

from __future__ import annotations

import argparse
import json
from collections.abc import Callable

from ... import limits as lim
from ...limits.views import band_texts, decimals
from ...model.scene import IMPACT_OBLIQUITY
from ...registry.plugin_registry import PluginRegistry
from ...run.progress import reporting_scenes
from ...storage.together import write_together
from ..common import (
    UsageError,
    add_dpi_option,
    check_directory,
    csv_text,
    figure_output,
    text_output,
)
from ..formatting import AXES, number, shown, unit
from ..limit_options import (
    OUTCOMES,
    add_archive_options,
    is_range,
    span,
    step,
    store,
    values,
    writable_archive,
)
from ..options import add_body_options, add_model_options, bodies, model_choice, typed
from ..writer import Writer


def arguments(p: argparse.ArgumentParser, registry: PluginRegistry) -> None:
    p.description = (
        "Lines along impact speed at fixed obliquities (--obliquities a list, "
        "--speeds a range START:STOP, default 50:2000) or along obliquity at fixed speeds "
        "(--speeds a list, --obliquities a range, default 0:89). Lists are comma lists or "
        "START:STOP:N."
    )
    p.add_argument("--speeds", help="impact speeds [m/s]: a range START:STOP, or lines")
    p.add_argument("--obliquities", help="impact obliquities [deg]: lines, or a range")
    p.add_argument(
        "--tolerance",
        help="width of each boundary's bracket [m/s or deg] (default 0.01 m/s, 0.001 deg)",
    )
    p.add_argument(
        "--resolution",
        help="no band this wide [m/s or deg] is missed (default 1 m/s, 0.1 deg)",
    )
    p.add_argument(
        "--outcome",
        action="append",
        metavar="OUTCOME",
        help=f"print only the bands of this outcome ({', '.join(OUTCOMES)}); repeatable",
    )
    p.add_argument(
        "--force",
        action="store_true",
        help=f"scan more than {lim.MAX_SCAN_SCENES:,} scenes (memory stays bounded: they run "
        "10,000 at a time; the time does not)",
    )
    p.add_argument("--json", action="store_true", help="print one JSON object")
    p.add_argument("--csv", metavar="FILE", help="write the bands as CSV")
    p.add_argument("--png", metavar="FILE", help="draw the bands")
    add_dpi_option(p)
    add_archive_options(p, "PRESET_FAILURE")
    add_body_options(p, registry)
    add_model_options(p, registry)


def run(args: argparse.Namespace, registry: PluginRegistry, out: Writer) -> int:
    check_directory(args.csv, "--csv")
    check_directory(args.png, "--png", "figure")
    archive = writable_archive(args)
    for outcome in args.outcome or ():
        if outcome not in OUTCOMES:
            raise UsageError(f"--outcome must be one of {', '.join(OUTCOMES)}, got {outcome!r}")
    flags = typed(args)
    flags.update({"speeds": "--speeds", "impact_speed": "--speeds", "tolerance": "--tolerance",
                  "obliquities": "--obliquities", "impact_obliquity": "--obliquities",
                  "resolution": "--resolution"})  # fmt: skip
    if args.obliquities is not None and not is_range(args.obliquities):
        along_speed = True
        if not is_range(args.speeds):
            raise UsageError("--speeds must be a range START:STOP with --obliquities as lines")
    elif args.speeds is not None and not is_range(args.speeds):
        along_speed = False
    else:
        raise UsageError(
            "give --obliquities as lines (a list or START:STOP:N: bands along speed) or "
            "--speeds as lines (bands along obliquity); the other, if given, as START:STOP"
        )
    choice = model_choice(args, registry)
    simulation = choice.simulation()
    sphere, plate, label = bodies(args, choice, simulation.model)
    degree = IMPACT_OBLIQUITY.scale  # what a typed obliquity is [rad]
    scale = 1.0 if along_speed else degree
    tolerance = lim.SPEED_TOLERANCE if along_speed else lim.OBLIQUITY_TOLERANCE
    resolution = lim.SPEED_RESOLUTION if along_speed else lim.OBLIQUITY_RESOLUTION
    if args.tolerance is not None:
        tolerance = step(args.tolerance, "--tolerance") * scale
        resolution = max(resolution, tolerance)  # a coarse tolerance: a coarse scan
    if args.resolution is not None:
        resolution = step(args.resolution, "--resolution") * scale
    if along_speed:
        lines = values(args.obliquities, "--obliquities", "deg") * degree
        extent = lim.SPEED_RANGE if args.speeds is None else span(args.speeds, "--speeds")
        find: Callable[..., lim.Limits] = lim.along_speed
    else:
        lines = values(args.speeds, "--speeds", "m/s")
        extent = lim.OBLIQUITY_RANGE
        if args.obliquities is not None:
            start, stop = span(args.obliquities, "--obliquities")
            extent = (start * degree, stop * degree)
        find = lim.along_obliquity
    with reporting_scenes("limits"):  # a count of scenes, per pass, on a terminal after 2 s
        found = find(
            simulation, sphere, plate, lines, extent, tolerance=tolerance, resolution=resolution,
            max_scenes=None if args.force else lim.MAX_SCAN_SCENES,
        )  # fmt: skip
    outputs = []  # the bands and their figure land together
    if args.csv is not None:
        outputs.append(text_output(args.csv, _csv(found), "--csv"))
    if args.png is not None:
        from ...figures.limits_and_maps import plot_bands  # noqa: PLC0415 (matplotlib when drawing)

        outputs.append(figure_output(plot_bands(found, label), args.png, "--png", args.dpi))
    write_together(outputs)
    if args.json:
        out.say(json.dumps({"preset": label, **found.to_json()}))
    else:
        _print(found, label, args.outcome, out)
    store(archive, args.name or f"{label}_{simulation.model.failure.name}", found, out)
    return 0


def _csv(found: lim.Limits) -> str:
    suffix = "deg" if found.axis == lim.OBLIQUITY else "m_s"
    fixed = "obliquity_deg" if found.axis == lim.SPEED else "speed_m_s"
    rows = []
    for line in found.to_json()["lines"]:
        for band in line["bands"]:
            rows.append([line[fixed], band["outcome"], band["plate_failed"],
                         band[f"from_{suffix}"], band[f"to_{suffix}"]])  # fmt: skip
    return csv_text([fixed, "outcome", "plate_failed", f"from_{suffix}", f"to_{suffix}"], rows)


def _print(found: lim.Limits, label: str, outcomes: list[str] | None, out: Writer) -> None:
    """Each line's bands and named limits in the axis's unit, to the decimals its
    tolerance resolves."""
    axis = AXES[found.axis]
    other = AXES[lim.OBLIQUITY if found.axis == lim.SPEED else lim.SPEED]
    digits = decimals(found.axis, found.tolerance)

    def show(x: float | None) -> str:
        return "none in range" if x is None else f"{number(axis, x, digits, 'f')} {unit(axis)}"

    for line in found.lines:
        bands = band_texts(found.axis, line, digits, outcomes)
        where = f"{number(other, line.fixed)} {unit(other)}"
        if found.axis == lim.SPEED:
            named = (
                f"ballistic limit {show(line.ballistic_limit)}, "
                f"ricochet limit {show(line.ricochet_limit)}"
            )
        else:
            named = f"critical ricochet obliquity {show(line.critical_ricochet_obliquity)}"
        shown_bands = " | ".join(bands) or "no such band"
        out.say(f"{shown(label, None)} at {where}: {shown_bands} {unit(axis)}; {named}")
    out.say(
        f"boundaries bracketed to {number(axis, found.tolerance)} {unit(axis)}, no band of "
        f"{number(axis, found.resolution)} {unit(axis)} missed; {found.scenes:,} scenes in "
        f"{found.seconds:.1f} s ({found.model['integrator']})"
    )
