"""``plateimpact show``: an archive's runs and stored limits, their metadata and a
summary (every piece of the archive's text printed inert: cli.describe)."""

from __future__ import annotations

import argparse

from ...registry.plugin_registry import PluginRegistry
from ...storage.archive import Archive
from ..describe import run_description
from ..stored_limits import show_stored
from ..writer import Writer


def arguments(parser: argparse.ArgumentParser, registry: PluginRegistry) -> None:
    parser.add_argument("archive", help="HDF5 archive")


def run(args: argparse.Namespace, registry: PluginRegistry, out: Writer) -> int:
    archive = Archive(args.archive)
    for name in archive.runs():
        out.say("\n".join(run_description(archive, name, registry)))
    show_stored(archive, out)
    return 0
