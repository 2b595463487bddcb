"""``plateimpact uncertainty``: distributions on a scene's inputs, propagated by direct
simulation: the probability of each outcome with its confidence interval, and exit-speed
and exit-obliquity quantiles (docs/uncertainty.md)."""

from __future__ import annotations

import argparse
import json

from ...registry.plugin_registry import PluginRegistry
from ...run.progress import reporting_scenes
from ...uncertainty import propagate, read_spec
from ...uncertainty.spec import MAX_SAMPLES, METHODS, with_settings
from ..writer import Writer


def arguments(p: argparse.ArgumentParser, registry: PluginRegistry) -> None:
    p.description = (
        "Sample the inputs that SPEC.json gives distributions (impact speed and obliquity, "
        "sphere radius and mass, plate thickness and constants, in their user units), run "
        "one scene per sample, and print the probability of ricochet, embedment and "
        "perforation with exact 95% binomial intervals, and exit quantiles."
    )
    p.add_argument("spec", metavar="SPEC.json", help="the study (docs/uncertainty.md)")
    p.add_argument(
        "--samples", type=int, help=f"samples to draw, in [2, {MAX_SAMPLES:,}] (the spec's)"
    )
    p.add_argument("--method", choices=METHODS, help="sampling (the spec's; default mc)")
    p.add_argument("--seed", type=int, help="the seed, in [0, 2**63) (the spec's; default 0)")
    p.add_argument("--json", action="store_true", help="print one JSON object")


def run(args: argparse.Namespace, registry: PluginRegistry, out: Writer) -> int:
    """Run ``plateimpact uncertainty``."""
    spec = read_spec(args.spec, registry)
    spec = with_settings(
        spec,
        "the command line",
        samples=spec.samples if args.samples is None else args.samples,
        method=spec.method if args.method is None else args.method,
        seed=spec.seed if args.seed is None else args.seed,
    )
    with reporting_scenes("uncertainty", spec.samples):
        found = propagate(spec, registry)
    summary = found.to_json()
    if args.json:
        out.say(json.dumps(summary, indent=2))
        return 0
    out.say(
        f"{spec.source}: {spec.samples:,} samples ({spec.method}, seed {spec.seed}) of "
        f"{', '.join(spec.inputs) or 'no input'}"
    )
    for name, probability in summary["probabilities"].items():
        low, high = summary["intervals"][name]
        out.say(f"  P({name:11s}) = {probability:.4f}   95% [{low:.4f}, {high:.4f}]")
    quantiles = summary["exit_quantiles"]
    levels = "/".join(f"{100 * q:g}" for q in quantiles["levels"])
    for key, label in (
        ("perforation_exit_speed_m_s", "perforation exit speed [m/s]"),
        ("ricochet_exit_obliquity_deg", "ricochet exit obliquity [deg]"),
    ):
        if quantiles[key] is not None:
            values = ", ".join(f"{v:.4g}" for v in quantiles[key])
            out.say(f"  {label}, quantiles {levels}%: {values}")
    return 0
