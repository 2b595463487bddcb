"""``reproduce``, ``show``, ``compare`` and ``plot``: archives of study runs."""

from __future__ import annotations

import argparse
import json
import math
from importlib.metadata import EntryPoint
from pathlib import Path
from typing import Any

import numpy as np

from ..discovery import (
    BrokenPackage,
    distribution_label,
    entry_point_label,
    first_line,
    installed_entry_points,
)
from ..errors import PluginError
from ..progress import progress_bar
from ..results import BatchResult, Outcome
from ..storage.archive import Archive
from ..study import Study, StudyResults
from .common import UsageError, check_directory
from .stored_limits import compare_stored, kinds, show_stored


def add_parsers(sub: Any) -> None:
    p = sub.add_parser("reproduce", help="run the report's figure families into one archive")
    p.add_argument("--out", default="report", help="output directory, created (default: report)")
    p.add_argument(
        "--resume",
        action="store_true",
        help="keep the runs already in DIR/report.h5 and run only the missing ones "
        "(default: add every run again, as NAME.2, ...)",
    )
    p.set_defaults(command_function=reproduce_command)

    p = sub.add_parser(
        "show", help="list an archive's runs and stored limits, their metadata and a summary"
    )
    p.add_argument("archive", help="HDF5 archive")
    p.set_defaults(command_function=show_command)

    p = sub.add_parser(
        "compare",
        help="compare two runs of an archive scene by scene, or two stored limits boundary "
        "by boundary",
    )
    p.add_argument("archive", help="HDF5 archive")
    p.add_argument("run_a", help="run name (STUDY/RUN, or RUN when unique), or stored limits")
    p.add_argument("run_b", help="run name (STUDY/RUN, or RUN when unique), or stored limits")
    p.add_argument("--png", metavar="FILE", help="overlay plot of the two runs")
    p.add_argument(
        "--json",
        action="store_true",
        help="print one JSON object: the runs' summary, or how each boundary of two stored "
        "limits moved (A, B: limits/NAME or NAME, as show lists them)",
    )
    p.set_defaults(command_function=compare_command)

    p = sub.add_parser(
        "plot", help="exit curves, trajectories or crater sections of runs in an archive"
    )
    p.add_argument("archive", help="HDF5 archive")
    p.add_argument("--run", required=True, action="append", help="run name (repeat to overlay)")
    p.add_argument("--out", required=True, metavar="FILE.png", help="where to draw")
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
    p.set_defaults(command_function=plot_command)


#: The entry-point group of runnable study collections; ``reproduce`` runs ``report``.
STUDIES_GROUP = "plateimpact.studies"


def study_collection(name: str) -> Any:
    """The object of the ``name`` entry point of :data:`STUDIES_GROUP`; a package that
    cannot be read or loaded is a one-line PluginError naming its distribution."""
    found: dict[str, EntryPoint] = {}
    broken = []
    for entry in installed_entry_points(STUDIES_GROUP):
        if isinstance(entry, BrokenPackage):
            broken.append(f"; {entry.describe()}")
        else:
            found.setdefault(entry.name, entry)  # the first on the path, as imports go
    if name not in found:
        raise PluginError(
            f"no study collection {name!r} is installed (entry-point group "
            f"{STUDIES_GROUP}){''.join(broken)}"
        )
    entry = found[name]
    try:
        return entry.load()
    except Exception as exc:
        raise PluginError(
            f"study collection {name!r} of {distribution_label(entry.dist)} (entry point "
            f"{entry_point_label(entry)}) failed to load: {first_line(exc)}"
        ) from None


def reproduce_command(args: argparse.Namespace) -> None:
    reproduce = study_collection("report")
    out = Path(args.out)
    if not str(args.out).strip():
        raise UsageError("--out: give a directory name")
    if out.exists() and not out.is_dir():
        raise UsageError(f"--out: {args.out!r} exists and is not a directory")
    if not out.parent.resolve().is_dir():
        raise UsageError(f"--out: directory {str(out.parent)!r} does not exist")
    archive, figures = reproduce(out, resume=args.resume)
    print(f"archive: {archive}")
    for figure in figures:
        print(f"figure:  {figure}")


def _study_results(archive: Archive, runs: list[str]) -> StudyResults:
    """The runs (named as users name them) of one study."""
    names = [archive.resolve(run) for run in runs]
    studies = {name.split("/", 1)[0] for name in names}
    if len(studies) != 1:
        raise UsageError(f"runs of one study only, got {', '.join(sorted(names))}")
    study = Study.from_archive(archive.path, studies.pop())
    return StudyResults(study, {name: archive.results(name) for name in names})


def show_command(args: argparse.Namespace) -> None:
    archive = Archive(args.archive)
    for name in archive.runs():
        meta: dict[str, Any] = archive.metadata(name)
        result: BatchResult = archive.results(name)
        variant = meta["variant"]
        counts = np.bincount(result.outcome, minlength=4)[1:]
        print(f"{name}")
        print(
            f"  model: {variant['resistance']} + {variant['failure']}, "
            f"integrator {variant['integrator']} {meta['model']['integrator_settings']}"
        )
        print(
            f"  {len(result)} scenes: {counts[0]} ricochet, {counts[1]} embedment, "
            f"{counts[2]} perforation; wall {meta['wall_time_s']:.2f} s"
        )
        kept = [
            what
            for what, data in (("trajectories", result.trajectory), ("craters", result.craters))
            if data is not None
        ]
        if kept:
            print(f"  with {' and '.join(kept)}")
        print(
            f"  run {meta['start_time']} on {meta['host']}, plateimpact "
            f"{meta['versions'].get('plateimpact')}, commit {meta['git_commit'][:12]}"
        )
    show_stored(archive)


def compare_command(args: argparse.Namespace) -> None:
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
        if args.png:
            raise UsageError("--png draws runs; stored limits are compared as text or --json")
        compare_stored(archive, args.run_a, args.run_b, args.json)
        return
    results = _study_results(archive, [args.run_a, args.run_b])
    name_a, name_b = archive.resolve(args.run_a), archive.resolve(args.run_b)
    comparison = results.compare(name_a, name_b)
    if args.json:
        print(json.dumps({"a": name_a, "b": name_b, **comparison.summary()}, indent=2))
    else:
        study = results.study
        scenes = study.scenes
        print(f"{name_b} against {name_a}: {len(results[name_a])} scenes")
        for i in comparison.changed:
            print(
                f"  {study.plate_labels[i]:>14} {np.degrees(scenes.impact_obliquity[i]):5.1f} "
                f"deg {scenes.impact_speed[i]:7.1f} m/s: "
                f"{Outcome(comparison.outcome_a[i]).label} -> "
                f"{Outcome(comparison.outcome_b[i]).label}"
            )
        print(json.dumps(comparison.summary(), indent=2))
    if args.png:
        from .. import plotting  # noqa: PLC0415 (matplotlib only when drawing)

        plotting.save(plotting.plot_study(results), args.png, "--png")


def plot_command(args: argparse.Namespace) -> None:
    from .. import plotting  # noqa: PLC0415 (matplotlib only when drawing)

    check_directory(args.out, "--out", "figure")
    for speed in args.speed or ():
        if not (math.isfinite(speed) and speed > 0.0):
            raise UsageError(f"--speed must be a finite impact speed > 0 m/s, got {speed}")
    with progress_bar(3, "plot", None, unit="stage") as stages:  # read, draw, save
        results = _study_results(Archive(args.archive), args.run)
        stages.update()
        if args.kind == "exit":
            figure = plotting.plot_study(results)
        else:
            try:
                figure = plotting.plot_study_paths(results, kind=args.kind, speeds=args.speed)
            except ValueError as exc:
                raise UsageError(str(exc)) from None
        stages.update()
        plotting.save(figure, args.out, "--out")
        stages.update()
    print(f"figure: {args.out}")
