"""The ``plateimpact`` command: user units (mm, m/s, g, degrees) in and out.

One module per command family; the options they share are built from the declarations
(:mod:`plateimpact.cli.options`). Every input error prints one line,
``plateimpact: error: ...``, and exits with code 2.
"""

from __future__ import annotations

import argparse
import sys
from collections.abc import Sequence

from ..errors import ParameterError, PlateImpactError
from ..registry import PluginRegistry, default_registry
from ..storage.provenance import versions
from . import archive_commands, calibrate, info, scene_commands
from .common import Parser, UsageError
from .options import flag_of
from .scene_commands import SWEEP_COLUMNS

__all__ = ["SWEEP_COLUMNS", "UsageError", "build_parser", "main"]


def build_parser(registry: PluginRegistry | None = None) -> argparse.ArgumentParser:
    """The argument parser of the ``plateimpact`` command (options from ``registry``)."""
    registry = registry or default_registry()
    parser = Parser(prog="plateimpact", description=(__doc__ or "").splitlines()[0])
    found = versions()
    parser.add_argument(
        "--version",
        action="version",
        version=f"plateimpact {found['plateimpact']} (python {found['python']}, numpy "
        f"{found['numpy']}, scipy {found['scipy']}, h5py {found['h5py']})",
    )
    sub = parser.add_subparsers(dest="command", required=True, parser_class=Parser)
    info.add_parsers(sub)
    scene_commands.add_parsers(sub, registry)
    calibrate.add_parsers(sub, registry)
    archive_commands.add_parsers(sub)
    return parser


def main(argv: Sequence[str] | None = None) -> int:
    """Entry point of the ``plateimpact`` command; returns the exit code."""
    args = argparse.Namespace()
    try:
        args = build_parser().parse_args(argv)
        args.command_function(args)
    except ParameterError as exc:
        flag = flag_of(args, exc.parameter)
        prefix = f"{flag}: " if flag else ""
        print(f"plateimpact: error: {prefix}{exc}", file=sys.stderr)
        return 2
    except PlateImpactError as exc:
        print(f"plateimpact: error: {exc}", file=sys.stderr)
        return 2
    except BrokenPipeError:  # e.g. piped into head
        sys.stderr.close()
        return 0
    return 0
