"""The plateimpact command: user units (mm, m/s, g, degrees) in and out.

One module per command (:mod:`plateimpact.cli.commands`), each with ``arguments`` and
``run``; ``main`` lists them from a table and imports only the one invoked, builds one
plug-in registry and hands it, with the one writer of the output, to the command. Every
input error prints one line, ``plateimpact: error: ...``, and exits with code 2; an
internal error prints one line naming the file that holds its traceback and exits with
code 1 (``--debug`` shows the traceback instead); an interrupt exits with code 130.
"""

from __future__ import annotations

import argparse
import importlib
import sys
import warnings
from collections.abc import Sequence
from types import ModuleType
from typing import TYPE_CHECKING, Any

from ..base.errors import ParameterError, PlateImpactError, PluginError
from .commands import COMMANDS, Command
from .common import Parser, UsageError
from .reporting import one_line_warnings, report_internal_error
from .writer import StdoutError, Writer

if TYPE_CHECKING:
    from ..registry.plugin_registry import PluginRegistry

__all__ = ["SWEEP_COLUMNS", "UsageError", "build_parser", "main"]

#: The packages whose versions ``--version`` names (as installed: nothing is imported).
VERSIONED = ("plateimpact", "numpy", "scipy", "h5py")


def __getattr__(name: str) -> Any:
    if name == "SWEEP_COLUMNS":  # the sweep's CSV columns, without importing it unasked
        from .sweep_csv import SWEEP_COLUMNS  # noqa: PLC0415

        return SWEEP_COLUMNS
    raise AttributeError(f"module {__name__!r} has no attribute {name!r}")


def _version() -> str:
    """``plateimpact 0.1.0 (python 3.11.7, numpy ..., scipy ..., h5py ...)``, from the
    installed distributions' metadata (importing numpy or scipy to ask would take longer
    than the rest of the command)."""
    import platform  # noqa: PLC0415
    from importlib import metadata  # noqa: PLC0415

    found = {}
    for package in VERSIONED:
        try:
            found[package] = metadata.version(package)
        except metadata.PackageNotFoundError:
            found[package] = "unknown"
    return (
        f"plateimpact {found['plateimpact']} (python {platform.python_version()}, numpy "
        f"{found['numpy']}, scipy {found['scipy']}, h5py {found['h5py']})"
    )


class _Version(argparse.Action):
    """``--version``: the line printed, computed only when asked for."""

    def __init__(self, option_strings: list[str], dest: str, **kwargs: Any) -> None:
        super().__init__(option_strings, dest, nargs=0, help="show the version and exit")

    def __call__(self, parser: argparse.ArgumentParser, *args: Any) -> None:
        parser._print_message(_version() + "\n")
        parser.exit()


def _parsers(out: Writer) -> tuple[Parser, dict[str, Parser]]:
    """The command's parser and an empty sub-parser per command (name and help from the
    table: no command imported)."""
    parser = Parser(prog="plateimpact", description=(__doc__ or "").splitlines()[0], out=out)
    parser.add_argument("--version", action=_Version)
    parser.add_argument(
        "--debug",
        action="store_true",
        help="on an internal error, raise it with its full traceback (default: one line "
        "and a traceback file)",
    )
    sub = parser.add_subparsers(dest="command", required=True, parser_class=Parser)
    found = {command.name: sub.add_parser(command.name, help=command.help, out=out)
             for command in COMMANDS}  # fmt: skip
    return parser, found


def _invoked(words: Sequence[str]) -> Command | None:
    """The command named on the command line: the first word that is not an option (the
    command's own options take no value), or None."""
    for word in words:
        if word == "--":
            return None
        if not word.startswith("-"):
            return next((c for c in COMMANDS if c.name == word), None)
    return None


def _module(command: Command) -> ModuleType:
    return importlib.import_module(f"{__name__}.commands.{command.module}")


def _add_arguments(module: ModuleType, parser: Parser, registry: PluginRegistry) -> None:
    """The command's options, from its module and the plug-ins of ``registry``."""
    try:
        module.arguments(parser, registry)
    except argparse.ArgumentError as exc:  # a plug-in's flag is one of the command's own
        raise PluginError(_flag_taken(registry, str(exc).rsplit(": ", 1)[-1])) from None


def build_parser(
    registry: PluginRegistry | None = None, out: Writer | None = None
) -> argparse.ArgumentParser:
    """The whole argument parser, every command's options added (options from
    ``registry``, default the installed plug-ins): for documentation and tests; ``main``
    adds only the invoked command's."""
    from ..registry.plugin_registry import default_registry  # noqa: PLC0415

    registry = default_registry() if registry is None else registry
    parser, found = _parsers(out or Writer())
    for command in COMMANDS:
        _add_arguments(_module(command), found[command.name], registry)
    return parser


def _flag_taken(registry: PluginRegistry, flag: str) -> str:
    """The message for a declared flag that the command line already has for itself (the
    registry refuses those of core quantities and of other plug-ins when registering)."""
    from ..registry.plugin_registry import KINDS  # noqa: PLC0415

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


def main(argv: Sequence[str] | None = None, *, registry: PluginRegistry | None = None) -> int:
    """Entry point of the ``plateimpact`` command; returns the exit code. ``registry``:
    the plug-ins the command uses (default: the installed ones, loaded once here)."""
    words = list(sys.argv[1:] if argv is None else argv)
    out = Writer()
    if out.closed():  # before any work: what it would print could not be seen
        return out.error("standard output is closed; redirect it (e.g. > /dev/null)")
    args = argparse.Namespace()
    with warnings.catch_warnings():  # restores the caller's warning display on return
        warnings.showwarning = one_line_warnings(warnings.showwarning, out)
        try:
            parser, found = _parsers(out)
            command = _invoked(words)
            if command is None:  # --version, --help, or argparse's one line on what is wrong
                parser.parse_args(words)
                return 2
            if registry is None:
                from ..registry.plugin_registry import default_registry  # noqa: PLC0415

                registry = default_registry()  # the one registry of this command
            module = _module(command)
            _add_arguments(module, found[command.name], registry)
            args = parser.parse_args(words)
            code: int = module.run(args, registry, out)
            out.flush()  # what is still buffered: its failure is the command's
            return code
        except ParameterError as exc:
            from .options import flag_of  # noqa: PLC0415

            flag = flag_of(args, exc.parameter, registry)
            prefix = f"{flag}: " if flag else ""
            return out.error(f"{prefix}{exc}")
        except PlateImpactError as exc:
            if isinstance(exc, StdoutError):
                out.discard()
            return out.error(exc)
        except BrokenPipeError:  # e.g. piped into head: the reader has what it wanted
            out.discard()
            sys.stderr.close()
            return 0
        except KeyboardInterrupt:
            out.line_to_stderr("plateimpact: interrupted")
            return 130
        except Exception as exc:  # a bug: one line, the traceback in a file
            # --debug is looked for in the words too: the parser may be what failed
            if getattr(args, "debug", False) or "--debug" in words:
                raise
            return report_internal_error(exc, words, out)
