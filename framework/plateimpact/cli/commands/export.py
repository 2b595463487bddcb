"""``plateimpact export``: one run of an archive as a netCDF-4 file or a tidy CSV table,
scene columns as the plug-ins of the registry declare them; or one stored record
(limits, an outcome map, an uncertainty study's result) as a netCDF-4 file."""

from __future__ import annotations

import argparse

from ...base.errors import ParameterError, UnknownNameError
from ...registry.plugin_registry import PluginRegistry
from ...storage.archive import Archive
from ...storage.output import write_output
from ...storage.records import LIMITS
from ..common import UsageError, check_directory, csv_text
from ..formatting import shown
from ..writer import Writer


def arguments(p: argparse.ArgumentParser, registry: PluginRegistry) -> None:
    p.add_argument("archive", help="HDF5 archive")
    which = p.add_mutually_exclusive_group(required=True)
    which.add_argument("--run", help="run name (STUDY/RUN, or RUN when unique)")
    which.add_argument(
        "--record",
        metavar="NAME",
        help="a stored record: limits, an outcome map or an uncertainty study's result "
        "(NAME or limits/NAME, as show lists them); --to FILE.nc only",
    )
    p.add_argument("--to", required=True, metavar="FILE", help="FILE.nc or FILE.csv")


def run(args: argparse.Namespace, registry: PluginRegistry, out: Writer) -> int:
    from ...storage import export  # noqa: PLC0415 (netCDF and table writing only here)

    try:
        kind = export.export_path_kind(args.to)
    except ParameterError as exc:
        raise UsageError(str(exc)) from None
    if args.record is not None and kind != "netcdf":
        raise UsageError(
            f"--to: a stored record is exported as netCDF-4 only: end the file name with .nc, "
            f"got {shown(args.to, None)}"
        )
    check_directory(args.to, "--to")
    archive = Archive(args.archive)
    if args.record is not None:
        data = _record_bytes(archive, args.record, registry)
        write_output(args.to, "--to", lambda handle: handle.write(data))
        stored = f"{LIMITS}/{args.record.removeprefix(f'{LIMITS}/')}"
        out.say(f"wrote {shown(stored, None)} to {shown(args.to, None)}")
        return 0
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


def _record_bytes(archive: Archive, name: str, registry: PluginRegistry) -> bytes:
    """The netCDF-4 file of the stored record ``name``, each kind laid out by the module
    that stores it."""
    from ...limits import archived as limits  # noqa: PLC0415
    from ...storage import export  # noqa: PLC0415
    from ...uncertainty import archived as uncertainty  # noqa: PLC0415

    kinds = {**limits.CF_RECORDS, **uncertainty.CF_RECORDS}
    try:
        return export.record_netcdf_bytes(archive, name, kinds, registry=registry)
    except UnknownNameError as exc:
        raise UsageError(f"--record: {exc}") from None
