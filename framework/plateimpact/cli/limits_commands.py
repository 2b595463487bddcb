"""``limits`` and ``map``: outcome bands, limits and outcome maps in user units."""

from __future__ import annotations

import argparse
import copy
import json
import math
from collections.abc import Callable
from typing import Any

import numpy as np

from .. import limits as lim
from ..base.errors import ArchiveError
from ..model.results import Outcome
from ..registry.plugin_registry import PluginRegistry
from ..run.progress import reporting_scenes
from ..storage.archive import Archive
from ..storage.together import write_together
from .common import (
    UsageError,
    add_dpi_option,
    check_directory,
    csv_text,
    figure_output,
    save_figure_atomically,
    say,
    text_output,
)
from .describe import shown
from .options import add_body_options, add_model_options, bodies, model_choice, typed

_DEG = math.pi / 180.0
OUTCOMES = tuple(o.label for o in Outcome)


def add_parsers(sub: Any, registry: PluginRegistry) -> None:
    p = sub.add_parser(
        "limits",
        help="outcome bands, ballistic and ricochet limits along speed or obliquity",
        description="Lines along impact speed at fixed obliquities (--obliquities a list, "
        "--speeds a range START:STOP, default 50:2000) or along obliquity at fixed speeds "
        "(--speeds a list, --obliquities a range, default 0:89). Lists are comma lists or "
        "START:STOP:N.",
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
    _add_archive(p, "PRESET_FAILURE")
    add_body_options(p, registry)
    add_model_options(p, registry)
    p.set_defaults(command_function=limits_command)

    p = sub.add_parser(
        "map",
        help="the outcome map of the (speed, obliquity) plane, or limit curves of plates",
    )
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
    _add_archive(p, "map_PRESET_FAILURE")
    add_body_options(p, registry, many_presets=True)
    add_model_options(p, registry)
    p.set_defaults(command_function=map_command)


def _add_archive(p: argparse.ArgumentParser, default: str) -> None:
    p.add_argument(
        "--archive", metavar="FILE", help="also store the result in this HDF5 archive (show, "
        "compare read it)",
    )  # fmt: skip
    p.add_argument(
        "--name",
        help=f"the stored name (default {default}, with '/' as '_'; NAME.2, ... if taken)",
    )


def _writable_archive(args: argparse.Namespace) -> Archive | None:
    """The --archive to store into, refused now if it could not take the result."""
    if args.name is not None and args.archive is None:
        raise UsageError("--name names what --archive stores; give --archive FILE")
    if args.archive is None:
        return None
    archive = Archive(args.archive)
    try:
        archive.check_writable()
    except ArchiveError as exc:  # a name too long, a read-only place, a damaged archive, ...
        raise UsageError(f"--archive: {exc}") from None
    return archive


def _store(archive: Archive | None, name: str, found: lim.Limits | lim.OutcomeMap) -> None:
    if archive is not None:
        stored = lim.archive_limits(archive, name.replace("/", "_"), found)
        say(f"archive: {archive.path} (limits/{stored})")


def _number(text: str, flag: str) -> float:
    try:
        value = float(text)
    except ValueError:
        raise UsageError(f"{flag} must be a number, got {text!r}") from None
    if not math.isfinite(value):
        raise UsageError(f"{flag} must be a finite number, got {text!r}")
    return value


def _step(text: str, flag: str) -> float:
    """A tolerance or resolution: any number, NaN and inf included, which the finder's
    check refuses naming the allowed range (docs/limits.md)."""
    try:
        return float(text)
    except ValueError:
        raise UsageError(f"{flag} must be a number, got {text!r}") from None


def _values(text: str, flag: str, unit: str) -> np.ndarray:
    """A comma list or START:STOP:N (N >= 1) [unit]."""
    parts = text.split(":")
    if len(parts) == 3:
        start, stop = _number(parts[0], flag), _number(parts[1], flag)
        try:
            count = int(parts[2])
        except ValueError:
            count = 0
        if not 1 <= count <= lim.MAX_SCAN_SCENES:
            raise UsageError(f"{flag}: N in START:STOP:N must be in [1, 1000000], got {parts[2]!r}")
        return np.linspace(start, stop, count)
    if len(parts) == 1 and text.strip():
        return np.array([_number(x, flag) for x in text.split(",")])
    raise UsageError(f"{flag} must be a comma list or START:STOP:N in {unit}, got {text!r}")


def _range(text: str, flag: str) -> tuple[float, float]:
    start, _, stop = text.partition(":")
    return _number(start, flag), _number(stop, flag)


def _is_range(text: str | None) -> bool:
    return text is None or text.count(":") == 1


def limits_command(args: argparse.Namespace) -> None:
    check_directory(args.csv, "--csv")
    check_directory(args.png, "--png", "figure")
    archive = _writable_archive(args)
    for outcome in args.outcome or ():
        if outcome not in OUTCOMES:
            raise UsageError(f"--outcome must be one of {', '.join(OUTCOMES)}, got {outcome!r}")
    flags = typed(args)
    flags.update({"speeds": "--speeds", "impact_speed": "--speeds", "tolerance": "--tolerance",
                  "obliquities": "--obliquities", "impact_obliquity": "--obliquities",
                  "resolution": "--resolution"})  # fmt: skip
    if args.obliquities is not None and not _is_range(args.obliquities):
        along_speed = True
        if not _is_range(args.speeds):
            raise UsageError("--speeds must be a range START:STOP with --obliquities as lines")
    elif args.speeds is not None and not _is_range(args.speeds):
        along_speed = False
    else:
        raise UsageError(
            "give --obliquities as lines (a list or START:STOP:N: bands along speed) or "
            "--speeds as lines (bands along obliquity); the other, if given, as START:STOP"
        )
    choice = model_choice(args)
    simulation = choice.simulation()
    sphere, plate, label = bodies(args, choice, simulation.model)
    scale = 1.0 if along_speed else _DEG
    tolerance = lim.SPEED_TOLERANCE if along_speed else lim.OBLIQUITY_TOLERANCE
    resolution = lim.SPEED_RESOLUTION if along_speed else lim.OBLIQUITY_RESOLUTION
    if args.tolerance is not None:
        tolerance = _step(args.tolerance, "--tolerance") * scale
        resolution = max(resolution, tolerance)  # a coarse tolerance: a coarse scan
    if args.resolution is not None:
        resolution = _step(args.resolution, "--resolution") * scale
    if along_speed:
        lines = _values(args.obliquities, "--obliquities", "deg") * _DEG
        span = lim.SPEED_RANGE if args.speeds is None else _range(args.speeds, "--speeds")
        find: Callable[..., lim.Limits] = lim.along_speed
    else:
        lines = _values(args.speeds, "--speeds", "m/s")
        span = lim.OBLIQUITY_RANGE
        if args.obliquities is not None:
            start, stop = _range(args.obliquities, "--obliquities")
            span = (start * _DEG, stop * _DEG)
        find = lim.along_obliquity
    with reporting_scenes("limits"):  # a count of scenes, per pass, on a terminal after 2 s
        found = find(
            simulation, sphere, plate, lines, span, tolerance=tolerance, resolution=resolution,
            max_scenes=None if args.force else lim.MAX_SCAN_SCENES,
        )  # fmt: skip
    outputs = []  # the bands and their figure land together
    if args.csv is not None:
        outputs.append(text_output(args.csv, _csv(found), "--csv"))
    if args.png is not None:
        from ..figures.limits_and_maps import plot_bands  # noqa: PLC0415 (matplotlib when drawing)

        outputs.append(figure_output(plot_bands(found, label), args.png, "--png", args.dpi))
    write_together(outputs)
    if args.json:
        say(json.dumps({"preset": label, **found.to_json()}))
    else:
        _print(found, label, args.outcome)
    _store(archive, args.name or f"{label}_{simulation.model.failure.name}", found)


def _csv(found: lim.Limits) -> str:
    unit = "deg" if found.axis == lim.OBLIQUITY else "m_s"
    fixed = "obliquity_deg" if found.axis == lim.SPEED else "speed_m_s"
    rows = []
    for line in found.to_json()["lines"]:
        for band in line["bands"]:
            rows.append([line[fixed], band["outcome"], band["plate_failed"],
                         band[f"from_{unit}"], band[f"to_{unit}"]])  # fmt: skip
    return csv_text([fixed, "outcome", "plate_failed", f"from_{unit}", f"to_{unit}"], rows)


def _print(found: lim.Limits, label: str, outcomes: list[str] | None) -> None:
    along_speed = found.axis == lim.SPEED
    scale, unit = (1.0, "m/s") if along_speed else (_DEG, "deg")
    digits = max(0, -math.floor(math.log10(found.tolerance / scale)))

    def show(x: float | None) -> str:
        return "none in range" if x is None else f"{x / scale:.{digits}f} {unit}"

    for line in found.lines:
        bands = [
            f"{b.regime.label} {b.start / scale:.{digits}f}-{b.end / scale:.{digits}f}"
            for b in line.bands
            if not outcomes or b.regime.outcome.label in outcomes
        ]
        if along_speed:
            where = f"{line.fixed / _DEG:g} deg"
            named = (
                f"ballistic limit {show(line.ballistic_limit)}, "
                f"ricochet limit {show(line.ricochet_limit)}"
            )
        else:
            where = f"{line.fixed:g} m/s"
            named = f"critical ricochet obliquity {show(line.critical_ricochet_obliquity)}"
        shown_bands = " | ".join(bands) or "no such band"
        say(f"{shown(label, None)} at {where}: {shown_bands} {unit}; {named}")
    say(
        f"boundaries bracketed to {found.tolerance / scale:g} {unit}, no band of "
        f"{found.resolution / scale:g} {unit} missed; {found.scenes:,} scenes in "
        f"{found.seconds:.1f} s ({found.model['integrator']})"
    )


def map_command(args: argparse.Namespace) -> None:
    check_directory(args.png, "--png", "figure")
    archive = _writable_archive(args)
    typed(args).update({"speeds": "--speeds", "impact_speed": "--speeds",
                        "obliquities": "--obliquities", "impact_obliquity": "--obliquities",
                        "tolerance": "--tolerance", "speed_samples": "--speeds"})  # fmt: skip
    parts = args.speeds.split(":")
    if len(parts) != 3:
        raise UsageError(f"--speeds must be START:STOP:N in m/s, got {args.speeds!r}")
    span = (_number(parts[0], "--speeds"), _number(parts[1], "--speeds"))
    try:
        samples = int(parts[2])
    except ValueError:
        raise UsageError(f"--speeds: N must be an integer >= 2, got {parts[2]!r}") from None
    rows = _values(args.obliquities, "--obliquities", "deg") * _DEG
    tolerance = _step(args.tolerance, "--tolerance")
    presets_given = args.preset or [None]
    if args.kind == "outcomes" and len(presets_given) > 4:
        raise UsageError("--preset: an outcome map draws at most 4 plates (one panel each)")
    choice = model_choice(args)
    simulation = choice.simulation()
    plates = []
    for preset in presets_given:
        given = copy.copy(args)
        given.preset = preset
        plates.append(bodies(given, choice, simulation.model))
    spheres = {sphere for sphere, _, _ in plates}  # one, from --radius and --mass
    with reporting_scenes("map"):
        found = lim.outcome_maps(simulation, spheres.pop(), [plate for _, plate, _ in plates],
                                 span, samples, rows, tolerance=tolerance)  # fmt: skip
    maps = [(label, one) for (_, _, label), one in zip(plates, found, strict=True)]
    shape, counted = found[0].shape, found[0].limits
    say(
        f"{', '.join(shown(label, None) for label, _ in maps)}: {len(maps)} map(s) of {shape[0]} x "
        f"{shape[1]}, {counted.scenes:,} scenes in {counted.seconds:.1f} s"
    )
    from ..figures.limits_and_maps import plot_limit_curves, plot_outcome_map  # noqa: PLC0415

    draw = plot_outcome_map if args.kind == "outcomes" else plot_limit_curves
    save_figure_atomically(draw(maps), args.png, dpi=args.dpi)
    say(f"figure:  {args.png}")
    failure = simulation.model.failure.name
    for label, drawn in maps:
        name = f"map_{label}_{failure}"
        if args.name:
            name = args.name if len(maps) == 1 else f"{args.name}_{label}"
        _store(archive, name, drawn)
