"""``plateimpact upgrade``: a format-1 archive rewritten as format 2 (an index and its
data files); the old file is kept as ARCHIVE.format1.h5."""

from __future__ import annotations

import argparse

from ...registry.plugin_registry import PluginRegistry
from ..writer import Writer


def arguments(p: argparse.ArgumentParser, registry: PluginRegistry) -> None:
    p.add_argument("archive", help="HDF5 archive of format version 1")


def run(args: argparse.Namespace, registry: PluginRegistry, out: Writer) -> int:
    from ...storage.upgrade import upgrade  # noqa: PLC0415

    kept = upgrade(args.archive, registry=registry)
    out.say(f"upgraded {args.archive} to format 2; the format-1 file is kept as {kept}")
    return 0
