"""``plateimpact reproduce``: the report's figure families, run into one archive (the
study collection ``report`` of the entry-point group ``plateimpact.studies``)."""

from __future__ import annotations

import argparse
import os
from importlib.metadata import EntryPoint
from pathlib import Path
from typing import Any

from ...base.errors import ArchiveError, PluginError
from ...base.untrusted import printable
from ...registry.discovery import (
    BrokenPackage,
    distribution_label,
    entry_point_label,
    first_line,
    installed_entry_points,
)
from ...registry.plugin_registry import PluginRegistry
from ...storage.append import RunExistsError
from ...storage.archive import Archive
from ...storage.confined import check_lengths
from ..common import UsageError, add_dpi_option, output_directory
from ..writer import Writer


def arguments(p: argparse.ArgumentParser, registry: PluginRegistry) -> None:
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


def run(args: argparse.Namespace, registry: PluginRegistry, out: Writer) -> int:
    from ...study.reruns import StaleRunError  # noqa: PLC0415 (hashing only when asked)

    reproduce = study_collection("report")
    if args.out is None:  # a quick archive holds other scenes: never the full one's place
        args.out = "report-quick" if args.quick else "report"
    where = Path(args.out)
    if not str(args.out).strip():
        raise UsageError("--out: give a directory name")
    _check_out_names(where)
    if args.tag is not None and not _printable_tag(args.tag):
        raise UsageError(f"--as: give a printable tag without '/' or spaces, got {args.tag!r}")
    output_directory(args.out, "--out", REPRODUCE_SPARE)  # checked and created, or one line
    _check_out_archive(where)
    try:
        # quick only when asked: a collection of an older signature still runs in full
        quick = {"quick": True} if args.quick else {}
        archive, figures = reproduce(
            where, None, args.resume, args.overwrite, args.tag, dpi=args.dpi, suffix=args.format,
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
    out.say(f"archive: {archive}")
    for figure in figures:
        out.say(f"figure:  {figure}")
    return 0


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
