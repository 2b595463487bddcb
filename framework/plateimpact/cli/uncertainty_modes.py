"""What ``plateimpact uncertainty`` does besides propagating one condition: Sobol'
indices (of P(perforation) and of the ballistic limit) and probability curves and maps
over a grid of speeds and obliquities, each kept in ``--archive`` and read back on
``--resume``; and what every mode shares (provenance, the archive, the figure's small
print). The limits mode is cli.uncertainty_limits."""

from __future__ import annotations

import argparse
import json
from typing import Any

import numpy as np

from ..base.errors import MissingExtraError
from ..model.bodies import THICKNESS
from ..provenance.metadata import versions
from ..run.progress import reporting_scenes
from ..run.simulation import Simulation
from ..storage.archive import Archive
from ..uncertainty.kept import Kept, kept_indices, kept_map
from ..uncertainty.spec import UncertaintySpec, UncertaintySpecError
from .common import UsageError, save_figure_atomically
from .formatting import quantity, shown
from .limit_options import values
from .writer import Writer

#: What --sobol-of may ask for.
SOBOL_OF = ("perforation", "ballistic_limit", "both")


def provenance(simulation: Simulation) -> dict[str, object]:
    """What produced the numbers: the model's plug-ins with their settings, and versions."""
    return {"model": simulation.describe(), "versions": versions()}


def figure_provenance(
    spec: UncertaintySpec, simulation: Simulation, sampled: str | None = None
) -> str:
    """A figure's small print: the plate, the model, how the inputs were sampled (by
    default the spec's samples) and the version."""
    model = simulation.describe()
    thickness = quantity(THICKNESS, spec.plate.thickness, 3)
    inputs = ", ".join(spec.inputs) or "no input"
    if sampled is None:
        sampled = f"{spec.samples:,} samples ({spec.method}, seed {spec.seed})"
    return (
        f"{spec.plate.material} {thickness}; {model['resistance']} + {model['failure']}, "
        f"{model['integrator']}; {sampled} of {inputs} from {spec.source}; plateimpact "
        f"{versions().get('plateimpact')}"
    )


def plate_title(spec: UncertaintySpec) -> str:
    return f"{spec.plate.material}, {quantity(THICKNESS, spec.plate.thickness, 3)}"


def archive_of(args: argparse.Namespace) -> Archive | None:
    return None if args.archive is None else Archive(args.archive)


def stored(kept: Kept, out: Writer) -> None:
    """Say where the result is kept, if it is."""
    if kept.archive is not None:
        out.say(f"archive: {shown(kept.archive.path, None)} ({kept.record})")


def check_sobol(spec: UncertaintySpec, args: argparse.Namespace) -> tuple[int, list[str]]:
    """--sobol N and --sobol-of, checked before any scene runs."""
    base = args.sobol
    if not (16 <= base <= 2**20 and base & (base - 1) == 0):
        raise UsageError(f"--sobol: a power of 2 in [16, {2**20:,}], got {base}")
    quantities = ["perforation", "ballistic_limit"] if args.sobol_of == "both" else [args.sobol_of]
    if "ballistic_limit" in quantities and "speed_m_s" in spec.inputs:
        raise UsageError(
            f"--sobol-of {args.sobol_of}: the ballistic limit is a speed: its indices take "
            f"inputs.speed_m_s without a distribution (give it in at); {spec.source} gives it one"
        )
    if "perforation" in quantities and not ("speed_m_s" in spec.at or "speed_m_s" in spec.inputs):
        raise UncertaintySpecError(
            f"{spec.source}: speed_m_s: P(perforation) is at a speed: give it in at or in inputs "
            "(or --sobol-of ballistic_limit)"
        )
    if len(spec.inputs) < 2:
        raise UncertaintySpecError(f"{spec.source}: inputs: --sobol needs two or more")
    return base, quantities


def sobol(
    spec: UncertaintySpec, simulation: Simulation, args: argparse.Namespace, out: Writer
) -> int:
    registry = simulation.registry
    base, quantities = check_sobol(spec, args)
    runs = None if "ballistic_limit" in quantities else base * (len(spec.inputs) + 2)
    try:
        with reporting_scenes("uncertainty --sobol", runs):
            found, kept = kept_indices(
                spec, registry, base, quantities, archive_of(args), resume=args.resume,
                simulation=simulation,
            )  # fmt: skip
    except MissingExtraError as exc:  # SALib, asked for before any point runs
        raise UsageError(f"--sobol: {exc}") from None
    if args.png is not None:
        from ..figures.sensitivity_bars import plot_sobol_indices  # noqa: PLC0415

        sampled = f"Saltelli's points, N = {base} (seed {spec.seed})"
        small = figure_provenance(spec, simulation, sampled)
        figure = plot_sobol_indices(found, plate_title(spec), small)
        save_figure_atomically(figure, args.png, dpi=args.dpi)
    summary: dict[str, Any] = {"base_samples": base}
    summary |= {q: indices.to_json() for q, indices in found.items()}
    summary |= {"spec": spec.describe(), **provenance(simulation)}
    if args.json:
        out.say(json.dumps({**summary, "archive_record": kept.record}, indent=2))
        return 0
    where = (
        "at each point's obliquity"
        if "obliquity_deg" in spec.inputs
        else f"at {spec.at['obliquity_deg']:g} deg"
    )
    for quantity_name, indices in found.items():
        what = (
            f"perforation, {indices.evaluations:,} runs"
            if quantity_name == "perforation"
            else f"the ballistic limit {where}, {indices.evaluations:,} limits"
        )
        out.say(f"{spec.source}: Sobol' indices of {what}")
        for input_name, index in summary[quantity_name]["indices"].items():
            first, total = index["first_interval"], index["total_interval"]
            out.say(
                f"  {input_name:14s} S1 {index['first']:6.3f} [{first[0]:6.3f}, {first[1]:6.3f}]"
                f"   ST {index['total']:6.3f} [{total[0]:6.3f}, {total[1]:6.3f}]"
            )
        out.say(f"  dominant: {indices.dominant()}")
    stored(kept, out)
    if args.png is not None:
        out.say(f"figure: {args.png}")
    return 0


def check_grid(args: argparse.Namespace) -> tuple[np.ndarray | None, np.ndarray | None]:
    """--speeds and --obliquities; with --png, two or more of each (a map)."""
    speeds = None if args.speeds is None else values(args.speeds, "--speeds", "m/s")
    angles = None if args.obliquities is None else values(args.obliquities, "--obliquities", "deg")
    if args.png is not None and (
        speeds is None or angles is None or min(speeds.size, angles.size) < 2
    ):
        raise UsageError(
            "--png draws probability maps over the (speed, obliquity) plane: give --speeds and "
            "--obliquities two or more values each"
        )
    return speeds, angles


def grid(
    spec: UncertaintySpec, simulation: Simulation, args: argparse.Namespace, out: Writer
) -> int:
    speeds, angles = check_grid(args)
    with reporting_scenes("uncertainty"):
        found, kept = kept_map(
            spec, simulation.registry, speeds, angles, archive_of(args), resume=args.resume,
            simulation=simulation,
        )  # fmt: skip
    if args.png is not None:
        from ..figures.probability_maps import plot_probability_maps  # noqa: PLC0415

        figure = plot_probability_maps(
            found, title=plate_title(spec), provenance=figure_provenance(spec, simulation)
        )
        save_figure_atomically(figure, args.png, dpi=args.dpi)
    summary = {**found.to_json(), **provenance(simulation)}
    if args.json:
        out.say(json.dumps({**summary, "archive_record": kept.record}, indent=2))
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
    stored(kept, out)
    if args.png is not None:
        out.say(f"figure: {args.png}")
    return 0
