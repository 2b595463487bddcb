"""``plateimpact uncertainty``: distributions on a scene's inputs, propagated by direct
simulation: the probability of each outcome with its confidence interval, and exit-speed
and exit-obliquity quantiles (docs/uncertainty.md)."""

from __future__ import annotations

import argparse
import json

from ...model.bodies import THICKNESS
from ...provenance.metadata import versions
from ...registry.plugin_registry import PluginRegistry
from ...run.progress import reporting_scenes
from ...run.simulation import Simulation
from ...uncertainty import propagate, read_spec
from ...uncertainty.curves import outcome_grid
from ...uncertainty.limits import sampled_limits
from ...uncertainty.sensitivity import perforation_indices
from ...uncertainty.spec import (
    MAX_SAMPLES,
    METHODS,
    UncertaintySpec,
    UncertaintySpecError,
    with_settings,
)
from ..common import UsageError, add_dpi_option, check_directory, save_figure_atomically
from ..formatting import quantity
from ..limit_options import values
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
    p.add_argument(
        "--limits",
        action="store_true",
        help="find the ballistic limit of every sample at the spec's obliquity instead "
        "(the speed takes no distribution): V10, V50 and V90 with distribution-free 95%% "
        "intervals, the whole P(perforation | V) curve from one set of limits",
    )
    p.add_argument(
        "--sobol",
        type=int,
        metavar="N",
        help="instead: Sobol' first-order and total indices of perforation at the spec's "
        "condition to each uncertain input, from N x (inputs + 2) runs (N a power of 2, "
        "in [16, 1,048,576])",
    )
    p.add_argument("--png", metavar="FILE", help="with --sobol: draw the indices as bars")
    p.add_argument(
        "--speeds",
        metavar="SPEEDS",
        help="instead: outcome probabilities along impact speed [m/s], START:STOP:N or a "
        "list, the same samples of the other inputs at every speed",
    )
    p.add_argument(
        "--obliquities",
        metavar="ANGLES",
        help="the same along obliquity [deg] (with --speeds: over the plane)",
    )
    p.add_argument(
        "--archive",
        metavar="FILE",
        help="run the samples as a study of this archive (HDF5 index and netCDF runs): the "
        "samples, the spec and the model recorded; outcome probabilities only",
    )
    p.add_argument(
        "--resume", action="store_true", help="with --archive: read back the same spec's run"
    )
    p.add_argument("--json", action="store_true", help="print one JSON object")
    add_dpi_option(p)


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
    simulation = Simulation.from_names(failure=spec.failure, registry=registry)
    others = args.limits or args.sobol is not None or args.speeds or args.obliquities
    if args.archive is not None and others:
        raise UsageError(
            "--archive: the outcome probabilities only (not --limits, --sobol, --speeds or "
            "--obliquities)"
        )
    if args.resume and args.archive is None:
        raise UsageError("--resume reads back a run of --archive: give --archive FILE too")
    if args.png is not None and args.sobol is None:
        raise UsageError("--png draws the Sobol' indices: give --sobol N too")
    check_directory(args.png, "--png", "figure")
    if args.sobol is not None:
        return _sobol(spec, simulation, args, out)
    if args.speeds is not None or args.obliquities is not None:
        return _grid(spec, simulation, args, out)
    if args.limits:
        return _limits(spec, simulation, args, out)
    with reporting_scenes("uncertainty", spec.samples):
        found = propagate(
            spec, registry, simulation=simulation, archive=args.archive, resume=args.resume
        )
    summary = {**found.to_json(), **_provenance(simulation)}
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


def _provenance(simulation: Simulation) -> dict[str, object]:
    """What produced the numbers: the model's plug-ins with their settings, and versions."""
    return {"model": simulation.describe(), "versions": versions()}


def _limits(
    spec: UncertaintySpec, simulation: Simulation, args: argparse.Namespace, out: Writer
) -> int:
    registry = simulation.registry
    as_json = args.json
    if "obliquity_deg" in spec.inputs:
        raise UncertaintySpecError(
            f"{spec.source}: obliquity_deg: --limits finds limits at one obliquity: give it in at"
        )
    with reporting_scenes("uncertainty --limits"):
        found = sampled_limits(spec, registry, spec.at["obliquity_deg"], simulation=simulation)
    summary = {**found.to_json(), "spec": spec.describe(), **_provenance(simulation)}
    if as_json:
        out.say(json.dumps(summary, indent=2))
        return 0
    out.say(
        f"{spec.source}: ballistic limit of {spec.samples:,} samples ({spec.method}, seed "
        f"{spec.seed}) at {summary['obliquity_deg']:g} deg"
    )
    for name in ("V10", "V50", "V90"):
        q = summary[name]
        out.say(
            f"  {name} = {q['speed_m_s']:.1f} m/s   95% [{q['low_m_s']:.1f}, {q['high_m_s']:.1f}]"
        )
    beyond, below = summary["beyond_range"], summary["below_range"]
    if beyond or below:
        out.say(f"  {beyond} sample(s) never perforate in the range, {below} always do")
    return 0


def _sobol(
    spec: UncertaintySpec, simulation: Simulation, args: argparse.Namespace, out: Writer
) -> int:
    registry = simulation.registry
    base = args.sobol
    if not (16 <= base <= 2**20 and base & (base - 1) == 0):
        raise UsageError(f"--sobol: a power of 2 in [16, {2**20:,}], got {base}")
    if len(spec.inputs) < 2:
        raise UncertaintySpecError(f"{spec.source}: inputs: --sobol needs two or more")
    with reporting_scenes("uncertainty --sobol", base * (len(spec.inputs) + 2)):
        found = perforation_indices(spec, registry, base, simulation=simulation)
    if args.png is not None:
        from ...figures.sensitivity_bars import plot_sobol_indices  # noqa: PLC0415

        thickness = quantity(THICKNESS, spec.plate.thickness, 3)
        title = f"{spec.plate.material}, {thickness}: perforation"
        save_figure_atomically(plot_sobol_indices(found, title), args.png, dpi=args.dpi)
    summary = {**found.to_json(), "spec": spec.describe(), **_provenance(simulation)}
    if args.json:
        out.say(json.dumps(summary, indent=2))
        return 0
    out.say(f"{spec.source}: Sobol' indices of perforation, {found.evaluations:,} runs")
    for name, index in summary["indices"].items():
        first, total = index["first_interval"], index["total_interval"]
        out.say(
            f"  {name:14s} S1 {index['first']:6.3f} [{first[0]:6.3f}, {first[1]:6.3f}]   "
            f"ST {index['total']:6.3f} [{total[0]:6.3f}, {total[1]:6.3f}]"
        )
    out.say(f"  dominant: {found.dominant()}")
    if args.png is not None:
        out.say(f"figure: {args.png}")
    return 0


def _grid(
    spec: UncertaintySpec, simulation: Simulation, args: argparse.Namespace, out: Writer
) -> int:
    registry = simulation.registry
    speeds = None if args.speeds is None else values(args.speeds, "--speeds", "m/s")
    angles = None if args.obliquities is None else values(args.obliquities, "--obliquities", "deg")
    with reporting_scenes("uncertainty"):
        found = outcome_grid(spec, registry, speeds, angles, simulation=simulation)
    summary = {**found.to_json(), **_provenance(simulation)}
    if args.json:
        out.say(json.dumps(summary, indent=2))
        return 0
    probability, (low, high) = found.probabilities(), found.intervals()["perforation"]
    out.say(f"{spec.source}: {spec.samples:,} samples at each point; P(perforation), 95%")
    out.say("speed_m_s  obliquity_deg  P(ricochet)  P(embedment)  P(perforation)  [low, high]")
    for i, v in enumerate(found.speeds_m_s):
        for j, o in enumerate(found.obliquities_deg):
            out.say(
                f"{v:9.4g}  {o:13.4g}  {probability['ricochet'][i, j]:11.4f}  "
                f"{probability['embedment'][i, j]:12.4f}  "
                f"{probability['perforation'][i, j]:14.4f}  [{low[i, j]:.4f}, {high[i, j]:.4f}]"
            )
    return 0
