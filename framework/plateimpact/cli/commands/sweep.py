"""``plateimpact sweep``: a grid of impact speeds and obliquities, one CSV row per scene
(streamed a chunk at a time: cli.sweep_csv), its inputs and provenance beside it."""

from __future__ import annotations

import argparse
from typing import Any

import numpy as np

from ...model.bodies import Plate, Sphere
from ...model.results import Outcome
from ...model.scene import IMPACT_SPEED
from ...registry.plugin_registry import PluginRegistry
from ...run.progress import reporting_scenes
from ...run.simulation import Simulation
from ...storage.together import write_together
from ..common import UsageError, check_directory
from ..formatting import shown
from ..options import add_body_options, add_model_options, bodies, model_choice, scene_flags
from ..sidecar import csv_and_sidecar, sidecar
from ..sweep_csv import Sweep
from ..writer import Writer

#: The largest sweep without --force: a million scenes take about a minute and a half
#: (dopri5, one core); a larger grid is refused unless --force says it is meant.
MAX_SWEEP_SCENES = 1_000_000
#: The most values one of --speeds, --obliquities may give, --force or not: each list
#: is held whole (8 bytes a value), the grid never is.
MAX_SWEEP_VALUES = 10_000_000


def arguments(parser: argparse.ArgumentParser, registry: PluginRegistry) -> None:
    parser.add_argument(
        "--speeds", required=True, help="impact speeds [m/s]: START:STOP:N or a list"
    )
    parser.add_argument("--obliquities", required=True, help="impact obliquities [deg], a list")
    parser.add_argument(
        "--force",
        action="store_true",
        help=f"run a grid of more than {MAX_SWEEP_SCENES:,} scenes (the results are "
        "streamed to the output, so memory stays bounded; the time does not)",
    )
    add_body_options(parser, registry)
    add_model_options(parser, registry)
    parser.add_argument("--csv", metavar="FILE", help="write CSV here (default: stdout)")


def _parse_speeds(text: str) -> np.ndarray:
    try:
        if ":" not in text:
            return np.array([float(x) for x in text.split(",")])
        start, stop, count = text.split(":")
        ends, n = (float(start), float(stop)), int(count)
        if n < 1:
            raise ValueError
    except ValueError:
        raise UsageError(
            f"--speeds must be START:STOP:N (N >= 1) or a comma list in m/s, got {text!r}"
        ) from None
    for end in ends:  # before linspace, which turns an infinite end into NaNs
        IMPACT_SPEED.check(end)
    if n > MAX_SWEEP_VALUES:
        raise UsageError(f"--speeds: N must be <= {MAX_SWEEP_VALUES:,}, got {n:,}")
    return np.linspace(*ends, n)


def _parse_obliquities(text: str) -> np.ndarray:
    try:
        return np.array([float(x) for x in text.split(",")])
    except ValueError:
        raise UsageError(f"--obliquities must be a comma list in degrees, got {text!r}") from None


def sweep_inputs(
    args: argparse.Namespace, simulation: Simulation, sphere: Sphere, plate: Plate, label: str
) -> dict[str, Any]:
    """The inputs record of a sweep (provenance.metadata), for the sidecar of its --csv."""
    from ...provenance.metadata import inputs_record  # noqa: PLC0415 (only for --csv)

    return inputs_record(
        simulation,
        sphere,
        plate,
        label=label,
        speeds_m_s=args.speeds,
        obliquities_deg=args.obliquities,
    )


def _check_sweep_size(speeds: int, obliquities: int, force: bool) -> None:
    """At most MAX_SWEEP_SCENES scenes, unless ``force``."""
    if speeds * obliquities > MAX_SWEEP_SCENES and not force:
        raise UsageError(
            f"--speeds, --obliquities: {speeds:,} x {obliquities:,} = "
            f"{speeds * obliquities:,} scenes is more than a sweep runs unasked "
            f"({MAX_SWEEP_SCENES:,}); add --force to run them all"
        )


def run(args: argparse.Namespace, registry: PluginRegistry, out: Writer) -> int:
    check_directory(args.csv, "--csv")
    check_directory(args.csv and sidecar(args.csv), "--csv", "json")
    scene_flags(args, "--speeds", "--obliquities")
    choice = model_choice(args, registry)
    simulation = choice.simulation()
    sphere, plate, label = bodies(args, choice, simulation.model)
    speeds, obliquities = _parse_speeds(args.speeds), _parse_obliquities(args.obliquities)
    _check_sweep_size(speeds.size, obliquities.size, args.force)
    sweep = Sweep(simulation, sphere, plate, label, speeds, obliquities)
    texts = sweep.csv_chunks()  # the grid checked: nothing written yet
    with reporting_scenes("sweep", sweep.size):  # a bar on a terminal, after 2 s
        if args.csv is None:
            for text in texts:
                out.write(text)
            return 0
        record = sweep_inputs(args, simulation, sphere, plate, label)
        # the CSV and, beside it, what it holds: together, tied by the CSV's SHA-256
        write_together(csv_and_sidecar(args.csv, "--csv", texts, record))
    out.say(
        f"wrote {sweep.size} scenes to {shown(args.csv, None)}: "
        + ", ".join(f"{sweep.counts[o]} {o.label}" for o in Outcome)
    )
    out.say(f"inputs and provenance: {shown(sidecar(args.csv), None)}")
    return 0
