"""``export``: one run of an archive as a netCDF-4 file or a tidy CSV table; ``upgrade``:
a format-1 archive rewritten as format 2."""

from __future__ import annotations

import argparse
from typing import Any

from ..base.errors import ParameterError
from ..storage.archive import Archive
from ..storage.output import write_output
from .common import UsageError, check_directory, csv_text, say
from .describe import shown


def add_parsers(sub: Any) -> None:
    p = sub.add_parser(
        "export",
        help="write one run as netCDF-4 (FILE.nc: xarray, ncdump, Panoply) or a CSV table "
        "(FILE.csv: one row per scene, units in the header)",
    )
    p.add_argument("archive", help="HDF5 archive")
    p.add_argument("--run", required=True, help="run name (STUDY/RUN, or RUN when unique)")
    p.add_argument("--to", required=True, metavar="FILE", help="FILE.nc or FILE.csv")
    p.set_defaults(command_function=export_command)

    p = sub.add_parser(
        "upgrade",
        help="rewrite a format-1 archive (one file) as format 2 (an index and its data files); "
        "the old file is kept as ARCHIVE.format1.h5",
    )
    p.add_argument("archive", help="HDF5 archive of format version 1")
    p.set_defaults(command_function=upgrade_command)


def upgrade_command(args: argparse.Namespace) -> None:
    from ..storage.upgrade import upgrade  # noqa: PLC0415

    kept = upgrade(args.archive)
    say(f"upgraded {args.archive} to format 2; the format-1 file is kept as {kept}")


def export_command(args: argparse.Namespace) -> None:
    from ..storage import export  # noqa: PLC0415 (netCDF and table writing only here)

    try:
        kind = export.export_path_kind(args.to)
    except ParameterError as exc:
        raise UsageError(str(exc)) from None
    check_directory(args.to, "--to")
    archive = Archive(args.archive)
    run = archive.resolve(args.run)
    if kind == "netcdf":
        data = export.netcdf_bytes(archive, run)
        write_output(args.to, "--to", lambda handle: handle.write(data))
    else:
        text = csv_text(export.table_header(archive, run), export.table_rows(archive, run))
        write_output(args.to, "--to", lambda handle: handle.write(text.encode()))
    say(f"wrote {shown(run, None)} to {shown(args.to, None)}")
