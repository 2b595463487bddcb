"""``plateimpact uncertainty``: distributions on a scene's inputs, propagated by direct
simulation: the probability of each outcome with its confidence interval, and exit-speed
and exit-obliquity quantiles; or the sampled ballistic and ricochet limits
(cli.uncertainty_limits), Sobol' indices, curves and maps (cli.uncertainty_modes)
(docs/uncertainty.md)."""

from __future__ import annotations

import argparse
import json

from ...registry.plugin_registry import PluginRegistry
from ...run.progress import reporting_scenes
from ...run.simulation import Simulation
from ...uncertainty import propagate, read_spec
from ...uncertainty.spec import MAX_SAMPLES, METHODS, with_settings
from ..common import UsageError, add_dpi_option, check_directory
from ..uncertainty_limits import limits
from ..uncertainty_modes import SOBOL_OF, grid, provenance, sobol
from ..writer import Writer


def arguments(p: argparse.ArgumentParser, registry: PluginRegistry) -> None:
    p.description = (
        "Sample the inputs that SPEC.json gives distributions (impact speed and obliquity, "
        "sphere radius and mass, plate thickness and constants, in their user units), run "
        "one scene per sample, and print the probability of ricochet, embedment and "
        "perforation with exact 95% binomial intervals, and exit quantiles; or the sampled "
        "limits (--limits), Sobol' indices (--sobol), or probability curves and maps "
        "(--speeds, --obliquities)."
    )
    p.add_argument("spec", metavar="SPEC.json", help="the study (docs/uncertainty.md)")
    p.add_argument(
        "--samples", type=int, help=f"samples to draw, in [2, {MAX_SAMPLES:,}] (the spec's)"
    )
    p.add_argument("--method", choices=METHODS, help="sampling (the spec's; default mc)")
    p.add_argument("--seed", type=int, help="the seed, in [0, 2**63) (the spec's; default 0)")
    p.add_argument(
        "--limits",
        action="store_true",
        help="find the ballistic and ricochet limits of every sample at each obliquity of "
        "--obliquities (or the spec's) instead (the speed takes no distribution): V10, V50, "
        "V90 and sigma of each limit with distribution-free 95%% intervals, as v50 reports "
        "them; the whole P(perforation | V) and P(ricochet | V) curves from one set of limits",
    )
    p.add_argument(
        "--shots",
        metavar="SHOTS.csv",
        help="with --limits: go/no-go shots (the file v50 reads), fitted as v50 fits them "
        "(probit) at each obliquity they share with the limits, printed beside the model's "
        "and drawn on the same axes by --png",
    )
    p.add_argument(
        "--sobol",
        type=int,
        metavar="N",
        help="instead: Sobol' first-order and total indices at the spec's condition to each "
        "uncertain input, from N x (inputs + 2) evaluations (N a power of 2, in "
        "[16, 1,048,576])",
    )
    p.add_argument(
        "--sobol-of",
        choices=SOBOL_OF,
        help="with --sobol: of whether a sample perforates (perforation, the default), of its "
        "ballistic limit at the spec's obliquity (ballistic_limit: the speed takes no "
        "distribution), or both",
    )
    p.add_argument(
        "--png",
        metavar="FILE",
        help="draw: with --limits the velocity-response curves, with --sobol the indices as "
        "bars, with --speeds and --obliquities the probability maps",
    )
    p.add_argument(
        "--speeds",
        metavar="SPEEDS",
        help="instead: outcome probabilities along impact speed [m/s], START:STOP:N or a "
        "list, the same samples of the other inputs at every speed",
    )
    p.add_argument(
        "--obliquities",
        metavar="ANGLES",
        help="the same along obliquity [deg] (with --speeds: over the plane); with --limits: "
        "the obliquities of the limits",
    )
    p.add_argument(
        "--archive",
        metavar="FILE",
        help="keep the result in this HDF5 archive: the samples run as a study (the samples, "
        "the spec and the model recorded), the limits, indices and maps as records beside it",
    )
    p.add_argument(
        "--resume",
        action="store_true",
        help="with --archive: read back the same request's finished result instead of computing it",
    )
    p.add_argument("--json", action="store_true", help="print one JSON object")
    add_dpi_option(p)


def _check_flags(args: argparse.Namespace) -> None:
    """The flags that go together, refused in one line before any scene runs."""
    if args.resume and args.archive is None:
        raise UsageError("--resume reads back a result of --archive: give --archive FILE too")
    grid = args.speeds is not None or args.obliquities is not None
    if args.sobol is not None:
        others = {"--limits": args.limits, "--speeds": args.speeds is not None,
                  "--obliquities": args.obliquities is not None}  # fmt: skip
        given = [flag for flag, on in others.items() if on]
        if given:
            raise UsageError(f"--sobol: not with {', '.join(given)} (one result at a time)")
        for flag, value in (("--samples", args.samples), ("--method", args.method)):
            if value is not None:
                raise UsageError(
                    f"{flag}: not with --sobol, whose points are Saltelli's, N x (inputs + 2)"
                )
    elif args.sobol_of is not None:
        raise UsageError("--sobol-of says what --sobol N analyses: give --sobol N too")
    if args.shots is not None and not args.limits:
        raise UsageError("--shots go beside the sampled limits: give --limits too")
    if args.png is not None and not (args.limits or args.sobol is not None or grid):
        raise UsageError(
            "--png draws the limits' curves, the Sobol' indices or the probability maps: give "
            "--limits, --sobol N, or --speeds and --obliquities"
        )
    check_directory(args.png, "--png", "figure")


def run(args: argparse.Namespace, registry: PluginRegistry, out: Writer) -> int:
    """Run ``plateimpact uncertainty``."""
    spec = read_spec(args.spec, registry)
    spec = with_settings(
        spec,
        "the command line",
        samples=spec.samples if args.samples is None else args.samples,
        method=spec.method if args.method is None else args.method,
        seed=spec.seed if args.seed is None else args.seed,
        names=("--samples", "--method", "--seed"),
    )
    _check_flags(args)
    simulation = Simulation.from_names(failure=spec.failure, registry=registry)
    if args.sobol is not None:
        if args.sobol_of is None:
            args.sobol_of = "perforation"
        return sobol(spec, simulation, args, out)
    if args.limits:
        return limits(spec, simulation, args, out)
    if args.speeds is not None or args.obliquities is not None:
        return grid(spec, simulation, args, out)
    with reporting_scenes("uncertainty", spec.samples):
        found = propagate(
            spec, registry, simulation=simulation, archive=args.archive, resume=args.resume
        )
    summary = {**found.to_json(), **provenance(simulation)}
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
