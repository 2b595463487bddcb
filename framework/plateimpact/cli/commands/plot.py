"""``plateimpact plot``: exit curves, trajectories or crater sections of runs in an
archive, drawn to one file."""

from __future__ import annotations

import argparse
import math

from ...registry.plugin_registry import PluginRegistry
from ...run.progress import progress_bar
from ...storage.archive import Archive
from ..common import UsageError, add_dpi_option, check_directory
from ..study_runs import study_results
from ..writer import Writer


def arguments(p: argparse.ArgumentParser, registry: PluginRegistry) -> None:
    p.add_argument("archive", help="HDF5 archive")
    p.add_argument("--run", required=True, action="append", help="run name (repeat to overlay)")
    p.add_argument(
        "--out",
        required=True,
        metavar="FILE",
        help="where to draw; the format from the extension (.png, .svg, .pdf, ...)",
    )
    add_dpi_option(p)
    p.add_argument(
        "--kind",
        choices=("exit", "trajectory", "crater"),
        default="exit",
        help="exit speed and obliquity against impact speed (default); the centre's "
        "trajectories; crater sections (runs recorded with trajectories / craters)",
    )
    p.add_argument(
        "--speed",
        type=float,
        action="append",
        metavar="M_S",
        help="trajectory/crater: draw the scene nearest this impact speed (repeat; "
        "default: six spread over the range)",
    )


def run(args: argparse.Namespace, registry: PluginRegistry, out: Writer) -> int:
    from ...figures import saving  # noqa: PLC0415 (matplotlib only when drawing)
    from ...figures.exit_curves import plot_study  # noqa: PLC0415
    from ...figures.study_paths import plot_study_paths  # noqa: PLC0415

    check_directory(args.out, "--out", "figure")
    for speed in args.speed or ():
        if not (math.isfinite(speed) and speed > 0.0):
            raise UsageError(f"--speed must be a finite impact speed > 0 m/s, got {speed}")
    with progress_bar(3, "plot", None, unit="stage") as stages:  # read, draw, save
        results = study_results(Archive(args.archive), args.run)
        stages.update()
        if args.kind == "exit":
            figure = plot_study(results)
        else:
            try:
                figure = plot_study_paths(results, kind=args.kind, speeds=args.speed)
            except ValueError as exc:
                raise UsageError(str(exc)) from None
        stages.update()
        saving.save(figure, args.out, "--out", dpi=args.dpi)
        stages.update()
    out.say(f"figure: {args.out}")
    return 0
