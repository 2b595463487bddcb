"""``plateimpact compile``: compile the compiled path's program of every installed (resistance
law, failure model) pair now, in this process, rather than in the background on first use
(:mod:`plateimpact.solve.compiled.warming`): for an installation step, a CI job or a
cluster image. Programs already in the cache load in a fraction of a second."""

from __future__ import annotations

import argparse
import json
import time

from ...base.extras import FAST, optional
from ...registry.plugin_registry import PluginRegistry
from ...solve.compiled import program, warming
from ..writer import Writer


def arguments(parser: argparse.ArgumentParser, registry: PluginRegistry) -> None:
    parser.add_argument("--json", action="store_true", help="print JSON")


def run(args: argparse.Namespace, registry: PluginRegistry, out: Writer) -> int:
    optional("numba", "compile", FAST)  # one line, not one failure per pair
    pairs = warming.compiled_pairs(registry)
    start = time.perf_counter()
    done = warming.compile_pairs(pairs)
    took = time.perf_counter() - start
    failed = [name for name, state in done if state != "ready"]
    if args.json:
        out.say(
            json.dumps(
                {
                    "cache_directory": str(program.cache_directory()),
                    "pairs": dict(done),
                    "seconds": round(took, 2),
                },
                indent=2,
            )
        )
    else:
        for name, state in done:
            out.say(f"{name:40s} {state}")
        out.say(f"{len(done) - len(failed)} of {len(done)} ready in {took:.1f} s, cached in "
                f"{program.cache_directory()}")  # fmt: skip
    return 1 if failed else 0
