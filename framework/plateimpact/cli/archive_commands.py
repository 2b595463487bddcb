"""``reproduce``, ``show``, ``compare`` and ``plot``: archives of study runs."""

from __future__ import annotations

import argparse
import math
import os
from importlib.metadata import EntryPoint
from pathlib import Path
from typing import Any

from ..base.errors import ArchiveError, PluginError
from ..base.untrusted import printable
from ..registry.discovery import (
    BrokenPackage,
    distribution_label,
    entry_point_label,
    first_line,
    installed_entry_points,
)
from ..run.progress import progress_bar
from ..storage.append import RunExistsError
from ..storage.archive import Archive
from ..storage.confined import check_lengths
from ..study.study import Study, StudyResults
from .common import UsageError, add_dpi_option, check_directory, output_directory, say
from .describe import run_description
from .run_comparison import print_comparison
from .stored_limits import compare_stored, kinds, show_stored


def add_parsers(sub: Any) -> None:
    p = sub.add_parser("reproduce", help="run the report's figure families into one archive")
    p.add_argument(
        "--out",
        help="output directory, created (default: report, with --quick report-quick)",
    )
    p.add_argument(
        "--quick",
        action="store_true",
        help="a smoke test of the whole job in a few seconds: every study, variant, "
        "stored map and experiment tool, through the same code, on a few scenes each",
    )
    rerun = p.add_mutually_exclusive_group()
    rerun.add_argument(
        "--resume",
        action="store_true",
        help="keep the runs already in DIR/report.h5 and run only the missing ones "
        "(without --resume, --overwrite or --as, runs already there are refused)",
    )
    rerun.add_argument(
        "--overwrite", action="store_true", help="replace the runs already there (atomically)"
    )
    rerun.add_argument(
        "--as", dest="tag", metavar="TAG", help="store the new runs as VARIANT@TAG beside the old"
    )
    add_dpi_option(p)
    p.add_argument(
        "--format",
        choices=("png", "svg", "pdf"),
        default="png",
        help="the figures' format (default: png; svg and pdf are vector, for print)",
    )
    p.set_defaults(command_function=reproduce_command)

    p = sub.add_parser(
        "show", help="list an archive's runs and stored limits, their metadata and a summary"
    )
    p.add_argument("archive", help="HDF5 archive")
    p.set_defaults(command_function=show_command)

    p = sub.add_parser(
        "compare",
        help="compare two runs of an archive (outcome changes in ranges of impact speed), "
        "or two stored limits boundary by boundary",
    )
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
    p.set_defaults(command_function=compare_command)

    p = sub.add_parser(
        "plot", help="exit curves, trajectories or crater sections of runs in an archive"
    )
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
    p.set_defaults(command_function=plot_command)


#: The longest name of a file or directory [bytes] (Linux, macOS and the BSDs).
NAME_MAX = 255
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


#: Bytes of path kept for what reproduce writes inside --out: the archive's data files
#: (report.h5.d/STUDY.VARIANT.HASH.nc), the figures and their temporary names.
REPRODUCE_SPARE = 128


def reproduce_command(args: argparse.Namespace) -> None:
    from ..study.reruns import StaleRunError  # noqa: PLC0415 (hashing only when asked)

    reproduce = study_collection("report")
    if args.out is None:  # a quick archive holds other scenes: never the full one's place
        args.out = "report-quick" if args.quick else "report"
    out = Path(args.out)
    if not str(args.out).strip():
        raise UsageError("--out: give a directory name")
    _check_out_names(out)
    if args.tag is not None and not _printable_tag(args.tag):
        raise UsageError(f"--as: give a printable tag without '/' or spaces, got {args.tag!r}")
    output_directory(args.out, "--out", REPRODUCE_SPARE)  # checked and created, or one line
    _check_out_archive(out)
    try:
        # quick only when asked: a collection of an older signature still runs in full
        quick = {"quick": True} if args.quick else {}
        archive, figures = reproduce(
            out, None, args.resume, args.overwrite, args.tag, dpi=args.dpi, suffix=args.format,
            **quick,
        )  # fmt: skip
    except StaleRunError as exc:  # neither kept nor replaced unasked: say how to proceed
        raise UsageError(
            f"{exc.what}; --overwrite replaces it, --as TAG stores the new runs as "
            "VARIANT@TAG (and the maps as map_PLATE@TAG)"
        ) from None
    except RunExistsError as exc:
        raise UsageError(
            f"{str(exc).split(':', 1)[0]}: --resume keeps it (runs only what is missing), "
            "--overwrite replaces it, --as TAG stores the new runs as VARIANT@TAG"
        ) from None
    say(f"archive: {archive}")
    for figure in figures:
        say(f"figure:  {figure}")


#: The archive ``reproduce`` writes in its output directory (plateimpact_studies.reproduce).
REPORT_ARCHIVE = "report.h5"


def _check_out_names(out: Path) -> None:
    """--out: every name in the path within NAME_MAX, and the deepest file the archive in
    it makes within PATH_MAX, before anything is looked at or made."""
    for part in out.parts:
        if len(os.fsencode(part)) > NAME_MAX:
            raise UsageError(
                f"--out: the name {printable(part, 40)!r} is {len(os.fsencode(part))} bytes, "
                f"longer than NAME_MAX ({NAME_MAX})"
            )
    try:
        check_lengths(out / REPORT_ARCHIVE, Path(os.path.abspath(out)) / REPORT_ARCHIVE, "--out")
    except ArchiveError as exc:
        raise UsageError(str(exc)) from None


def _check_out_archive(out: Path) -> None:
    """Check that the archive in the output directory can be written (one line naming
    --out otherwise: a damaged archive, a shipped lock)."""
    try:
        Archive(out / REPORT_ARCHIVE).check_writable()
    except ArchiveError as exc:
        raise UsageError(f"--out: {exc}") from None


def _printable_tag(tag: str) -> bool:
    return bool(tag) and tag.isprintable() and "/" not in tag and not any(c.isspace() for c in tag)


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
        say("\n".join(run_description(archive, name)))
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
        if args.png or args.summary:
            what = "--png draws runs" if args.png else "--summary counts the outcomes of runs"
            raise UsageError(f"{what}; stored limits are compared as text or --json")
        compare_stored(archive, args.run_a, args.run_b, args.json)
        return
    results = _study_results(archive, [args.run_a, args.run_b])
    comparison = results.compare(archive.resolve(args.run_a), archive.resolve(args.run_b))
    print_comparison(comparison, as_json=args.json, summary=args.summary)
    if args.png:
        from ..figures import saving  # noqa: PLC0415 (matplotlib only when drawing)
        from ..figures.compared_runs import plot_comparison  # noqa: PLC0415

        saving.save(plot_comparison(comparison), args.png, "--png", dpi=args.dpi)
        if not args.json:
            say(f"figure: {args.png}")


def plot_command(args: argparse.Namespace) -> None:
    from ..figures import saving  # noqa: PLC0415 (matplotlib only when drawing)
    from ..figures.exit_curves import plot_study  # noqa: PLC0415
    from ..figures.study_paths import plot_study_paths  # noqa: PLC0415

    check_directory(args.out, "--out", "figure")
    for speed in args.speed or ():
        if not (math.isfinite(speed) and speed > 0.0):
            raise UsageError(f"--speed must be a finite impact speed > 0 m/s, got {speed}")
    with progress_bar(3, "plot", None, unit="stage") as stages:  # read, draw, save
        results = _study_results(Archive(args.archive), args.run)
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
    say(f"figure: {args.out}")
