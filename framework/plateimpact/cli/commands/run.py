"""``plateimpact run``: one scene, its result in user units (``--json``: one object with
its inputs and provenance, which ``run --inputs`` reads back)."""

from __future__ import annotations

import argparse
import json
from typing import Any

from ...model.results import RESULT_FIELDS, TRAJECTORY_FIELDS
from ...model.scene import IMPACT_OBLIQUITY, IMPACT_SPEED, Scene
from ...model.views import result_quantities
from ...registry.plugin_registry import PluginRegistry
from ...run.simulation import Simulation
from ...storage.together import write_together
from ..common import UsageError, check_directory, csv_text
from ..formatting import quantity, shown, user
from ..scenes import add_scene_options, scene_of
from ..sidecar import csv_and_sidecar, sidecar
from ..writer import Writer

#: The options of ``run`` that --inputs leaves free: what to print and write.
OUTPUT_OPTIONS = ("command", "debug", "inputs", "json", "trajectory")


def arguments(parser: argparse.ArgumentParser, registry: PluginRegistry) -> None:
    add_scene_options(parser, registry, required=False)  # --inputs gives them instead
    parser.add_argument("--json", action="store_true", help="print one JSON object")
    parser.add_argument("--trajectory", metavar="FILE", help="write the trajectory as CSV")
    parser.add_argument(
        "--inputs",
        metavar="FILE.json",
        help="run again, bit for bit, the scene a 'run --json' output recorded (its "
        "'inputs'); no scene, plate, sphere or model option with it",
    )


def _recorded_scene(
    args: argparse.Namespace, registry: PluginRegistry
) -> tuple[Scene, Simulation, str]:
    """The scene, simulation and label of ``run --inputs FILE``."""
    from ...provenance.inputs import load_run_inputs  # noqa: PLC0415 (only for --inputs)

    given = sorted(
        "--" + dest.replace("_", "-")
        for dest, value in vars(args).items()
        if dest not in OUTPUT_OPTIONS and not dest.startswith("_") and value not in (None, [])
    )
    if given:
        raise UsageError(
            f"--inputs cannot be combined with {', '.join(given)}: the file gives the whole "
            "scene and model (edit a copy of it to change one)"
        )
    recorded = load_run_inputs(args.inputs, registry=registry)
    return recorded.scene, recorded.simulation, recorded.label


def inputs_record(scene: Scene, simulation: Simulation, label: str) -> dict[str, Any]:
    """The run's inputs and provenance (source commit, code hashes): only where they are
    written or printed, never for the text output."""
    from ...provenance.metadata import inputs_record as record  # noqa: PLC0415

    return record(
        simulation,
        scene.sphere,
        scene.plate,
        label=label,
        scene={IMPACT_SPEED: scene.impact_speed, IMPACT_OBLIQUITY: scene.impact_obliquity},
    )


def run(args: argparse.Namespace, registry: PluginRegistry, out: Writer) -> int:
    check_directory(args.trajectory, "--trajectory")
    check_directory(args.trajectory and sidecar(args.trajectory), "--trajectory", "json")
    if args.inputs is not None:
        scene, simulation, label = _recorded_scene(args, registry)
    else:
        missing = [flag for flag in ("--speed", "--obliquity") if getattr(args, flag[2:]) is None]
        if missing:
            raise UsageError(
                f"the following arguments are required: {', '.join(missing)} (or --inputs)"
            )
        scene, simulation, label = scene_of(args, registry)
    result = simulation.run(scene, record_trajectory=args.trajectory is not None)
    # the record (source commit, code hashes) only where it is written or printed
    record = inputs_record(scene, simulation, label) if args.json or args.trajectory else None
    if args.trajectory is not None and result.trajectory is not None and record is not None:
        path = result.trajectory
        fields = list(TRAJECTORY_FIELDS.values())
        rows = zip(*(getattr(path, f.name) / f.scale for f in fields), strict=True)
        text = csv_text([f.key for f in fields], rows)
        # the path and, beside it, the run's inputs (run --inputs reads them): together
        write_together(csv_and_sidecar(args.trajectory, "--trajectory", [text], record))
    if args.json:
        found: dict[str, Any] = {
            "preset": label,
            IMPACT_SPEED.key: user(IMPACT_SPEED, scene.impact_speed),
            IMPACT_OBLIQUITY.key: user(IMPACT_OBLIQUITY, scene.impact_obliquity),
        }
        found.update(result.as_user_dict())
        found["model"] = simulation.describe()
        found["inputs"] = record
        out.say(json.dumps(found))
        return 0
    _print(out, scene, label, result)
    return 0


def _print(out: Writer, scene: Scene, label: str, result: Any) -> None:
    """The result as text, each quantity in the unit its declaration gives."""
    impact = (
        f"{quantity(IMPACT_SPEED, scene.impact_speed)} at "
        f"{quantity(IMPACT_OBLIQUITY, scene.impact_obliquity)}"
    )
    out.say(f"{shown(label, None)}: {impact} -> {result.outcome.label}")
    values = {name: getattr(result, name) for name in RESULT_FIELDS}
    for what, value in result_quantities(values):  # as the Result's repr says them
        out.say(f"  {what:16} {value}")
