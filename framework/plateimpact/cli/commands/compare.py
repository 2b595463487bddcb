"""``plateimpact compare``: two runs of an archive (outcome changes in ranges, as text,
counts or JSON, a figure), or two stored limits boundary by boundary."""

from __future__ import annotations

import argparse

from ...registry.plugin_registry import PluginRegistry
from ...storage.archive import Archive
from ..common import UsageError, add_dpi_option, check_directory
from ..run_comparison import print_comparison
from ..stored_limits import compare_stored, kinds
from ..study_runs import study_results
from ..writer import Writer


def arguments(p: argparse.ArgumentParser, registry: PluginRegistry) -> None:
    p.add_argument("archive", help="HDF5 archive")
    p.add_argument("run_a", help="run name (STUDY/RUN, or RUN when unique), or stored limits")
    p.add_argument("run_b", help="run name (STUDY/RUN, or RUN when unique), or stored limits")
    p.add_argument(
        "--png",
        metavar="FILE",
        help="runs: their exit speeds and obliquities overlaid, outcome changes shaded",
    )
    add_dpi_option(p)
    p.add_argument(
        "--summary",
        action="store_true",
        help="runs: counts only (scenes, outcome changes by pair, largest exit differences)",
    )
    p.add_argument(
        "--json",
        action="store_true",
        help="print one JSON object: the runs' outcome ranges (with --summary: their "
        "counts), or how each boundary of two stored limits moved (A, B: limits/NAME or "
        "NAME, as show lists them)",
    )


def run(args: argparse.Namespace, registry: PluginRegistry, out: Writer) -> int:
    check_directory(args.png, "--png", "figure")
    archive = Archive(args.archive)
    kind_a, kind_b = kinds(archive, [args.run_a, args.run_b])
    if kind_a != kind_b:
        run, stored = (args.run_a, args.run_b) if kind_a == "run" else (args.run_b, args.run_a)
        raise UsageError(
            f"{run!r} is a run and {stored!r} is stored limits: compare runs with runs, "
            "limits with limits"
        )
    if kind_a == "limits":
        if args.png or args.summary:
            what = "--png draws runs" if args.png else "--summary counts the outcomes of runs"
            raise UsageError(f"{what}; stored limits are compared as text or --json")
        compare_stored(archive, args.run_a, args.run_b, args.json, out)
        return 0
    results = study_results(archive, [args.run_a, args.run_b])
    comparison = results.compare(archive.resolve(args.run_a), archive.resolve(args.run_b))
    print_comparison(comparison, out, as_json=args.json, summary=args.summary)
    if args.png:
        from ...figures import saving  # noqa: PLC0415 (matplotlib only when drawing)
        from ...figures.compared_runs import plot_comparison  # noqa: PLC0415

        saving.save(plot_comparison(comparison), args.png, "--png", dpi=args.dpi)
        if not args.json:
            out.say(f"figure: {args.png}")
    return 0
