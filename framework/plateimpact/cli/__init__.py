"""The ``plateimpact`` command: user units (mm, m/s, g, degrees) in and out.

One module per command family; the options they share are built from the declarations
(:mod:`plateimpact.cli.options`). Every input error prints one line,
``plateimpact: error: ...``, and exits with code 2; an internal error prints one line
naming the file that holds its traceback and exits with code 1 (``--debug`` shows the
traceback instead); an interrupt exits with code 130.
"""

from __future__ import annotations

import argparse
import sys
import warnings
from collections.abc import Sequence

from ..base.errors import ParameterError, PlateImpactError, PluginError
from ..base.untrusted import printable
from ..provenance.metadata import versions
from ..registry.plugin_registry import KINDS, PluginRegistry, default_registry
from . import (
    archive_commands,
    calibrate,
    info,
    limits_commands,
    review_commands,
    scene_commands,
    v50_command,
    validate,
)
from .common import (
    Parser,
    StdoutError,
    UsageError,
    discard_stdout,
    flush_stdout,
    stdout_closed,
)
from .options import flag_of
from .reporting import one_line_warnings, report_internal_error
from .sweep_csv import SWEEP_COLUMNS

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
    parser.add_argument(
        "--debug",
        action="store_true",
        help="on an internal error, raise it with its full traceback (default: one line "
        "and a traceback file)",
    )
    sub = parser.add_subparsers(dest="command", required=True, parser_class=Parser)
    info.add_parsers(sub)
    try:
        scene_commands.add_parsers(sub, registry)
        calibrate.add_parsers(sub, registry)
        validate.add_parsers(sub, registry)
        limits_commands.add_parsers(sub, registry)
        v50_command.add_parsers(sub, registry)
    except argparse.ArgumentError as exc:  # a plug-in's flag is one of the command's own
        raise PluginError(_flag_taken(registry, str(exc).rsplit(": ", 1)[-1])) from None
    archive_commands.add_parsers(sub)
    review_commands.add_parsers(sub)
    return parser


def _flag_taken(registry: PluginRegistry, flag: str) -> str:
    """The message for a declared flag that the command line already has for itself (the
    registry refuses those of core quantities and of other plug-ins when registering)."""
    declarers = [
        f"{kind} {name!r} ({registry.get(kind, name).__module__})"
        for kind in KINDS
        for name in registry.names(kind)
        if any(
            declared.flag == flag
            for declared in (
                *registry.get(kind, name).setting_declarations().values(),
                *registry.get(kind, name).plate_constants,
            )
        )
    ]
    return (
        f"the plug-in {' and '.join(declarers) or 'option'} declares the flag {flag}, which "
        "is one of the command line's own options: the plug-in must declare another"
    )


def _error(message: object) -> int:
    """Print the one-line error (any character a terminal would act on escaped, so that
    a message quoting a file is still one inert line); the exit code, 2."""
    print(f"plateimpact: error: {printable(message)}", file=sys.stderr)
    return 2


def main(argv: Sequence[str] | None = None) -> int:
    """Entry point of the ``plateimpact`` command; returns the exit code."""
    arguments = list(sys.argv[1:] if argv is None else argv)
    if stdout_closed():  # before any work: what it would print could not be seen
        return _error("standard output is closed; redirect it (e.g. > /dev/null)")
    args = argparse.Namespace()
    with warnings.catch_warnings():  # restores the caller's warning display on return
        warnings.showwarning = one_line_warnings(warnings.showwarning)
        try:
            args = build_parser().parse_args(arguments)
            args.command_function(args)
            flush_stdout()  # what is still buffered: its failure is the command's
        except ParameterError as exc:
            flag = flag_of(args, exc.parameter)
            prefix = f"{flag}: " if flag else ""
            return _error(f"{prefix}{exc}")
        except PlateImpactError as exc:
            if isinstance(exc, StdoutError):
                discard_stdout()
            return _error(exc)
        except BrokenPipeError:  # e.g. piped into head
            discard_stdout()
            sys.stderr.close()
            return 0
        except KeyboardInterrupt:
            print("plateimpact: interrupted", file=sys.stderr)
            return 130
        except Exception as exc:  # a bug: one line, the traceback in a file
            # --debug is looked for in the words too: the parser may be what failed
            if getattr(args, "debug", False) or "--debug" in arguments:
                raise
            return report_internal_error(exc, arguments)
    return 0
