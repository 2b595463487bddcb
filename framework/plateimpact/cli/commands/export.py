"""``plateimpact export``: one run of an archive as a netCDF-4 file or a tidy CSV table,
scene columns as the plug-ins of the registry declare them."""

from __future__ import annotations

import argparse

from ...base.errors import ParameterError
from ...registry.plugin_registry import PluginRegistry
from ...storage.archive import Archive
from ...storage.output import write_output
from ..common import UsageError, check_directory, csv_text
from ..formatting import shown
from ..writer import Writer


def arguments(p: argparse.ArgumentParser, registry: PluginRegistry) -> None:
    p.add_argument("archive", help="HDF5 archive")
    p.add_argument("--run", required=True, help="run name (STUDY/RUN, or RUN when unique)")
    p.add_argument("--to", required=True, metavar="FILE", help="FILE.nc or FILE.csv")


def run(args: argparse.Namespace, registry: PluginRegistry, out: Writer) -> int:
    from ...storage import export  # noqa: PLC0415 (netCDF and table writing only here)

    try:
        kind = export.export_path_kind(args.to)
    except ParameterError as exc:
        raise UsageError(str(exc)) from None
    check_directory(args.to, "--to")
    archive = Archive(args.archive)
    run = archive.resolve(args.run)
    if kind == "netcdf":
        data = export.netcdf_bytes(archive, run, registry=registry)
        write_output(args.to, "--to", lambda handle: handle.write(data))
    else:
        header = export.table_header(archive, run, registry=registry)
        text = csv_text(header, export.table_rows(archive, run, registry=registry))
        write_output(args.to, "--to", lambda handle: handle.write(text.encode()))
    out.say(f"wrote {shown(run, None)} to {shown(args.to, None)}")
    return 0
