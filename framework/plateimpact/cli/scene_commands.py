"""``run``, ``crater`` and ``sweep``: scenes in user units, results in user units."""

from __future__ import annotations

import argparse
import json
from typing import Any

import numpy as np

from ..base.parameters import Parameter
from ..model.bodies import Plate, Sphere
from ..model.crater import crater_section
from ..model.results import CRATER_FIELDS, TRAJECTORY_FIELDS, Outcome
from ..model.scene import IMPACT_OBLIQUITY, IMPACT_SPEED, Scene
from ..provenance.inputs import load_run_inputs
from ..provenance.metadata import inputs_record
from ..registry.plugin_registry import PluginRegistry, default_registry
from ..run.progress import reporting_scenes
from ..run.simulation import Simulation
from ..storage.together import write_together
from .common import (
    UsageError,
    add_dpi_option,
    check_directory,
    csv_text,
    figure_output,
    say,
    text_output,
    write_stdout,
)
from .describe import shown
from .options import (
    add_body_options,
    add_model_options,
    bodies,
    metavar,
    model_choice,
    scene_flags,
)
from .sidecar import csv_and_sidecar, sidecar
from .sweep_csv import Sweep

#: The largest sweep without --force: a million scenes take about a minute and a half
#: (dopri5, one core); a larger grid is refused unless --force says it is meant.
MAX_SWEEP_SCENES = 1_000_000
#: The most values one of --speeds, --obliquities may give, --force or not: each list
#: is held whole (8 bytes a value), the grid never is.
MAX_SWEEP_VALUES = 10_000_000


def add_parsers(sub: Any, registry: PluginRegistry) -> None:
    commands = [
        ("run", run_command, "run one scene"),
        ("crater", crater_command, "the crater section of one scene (eqs 31-39)"),
        ("sweep", sweep_command, "run a grid of speeds and obliquities"),
    ]
    parsers = {}
    for name, function, summary in commands:
        p = parsers[name] = sub.add_parser(name, help=summary)
        if name == "sweep":
            p.add_argument(
                "--speeds", required=True, help="impact speeds [m/s]: START:STOP:N or a list"
            )
            p.add_argument("--obliquities", required=True, help="impact obliquities [deg], a list")
            p.add_argument(
                "--force",
                action="store_true",
                help=f"run a grid of more than {MAX_SWEEP_SCENES:,} scenes (the results are "
                "streamed to the output, so memory stays bounded; the time does not)",
            )
        else:
            for declared in (IMPACT_SPEED, IMPACT_OBLIQUITY):
                flag = declared.flag or ""
                # run checks them itself: --inputs gives them instead
                required = name != "run"
                p.add_argument(
                    flag, required=required, metavar=metavar(declared), help=declared.help()
                )
        add_body_options(p, registry)
        add_model_options(p, registry)
        p.set_defaults(command_function=function)
    parsers["run"].add_argument("--json", action="store_true", help="print one JSON object")
    parsers["run"].add_argument("--trajectory", metavar="FILE", help="write the trajectory as CSV")
    parsers["run"].add_argument(
        "--inputs",
        metavar="FILE.json",
        help="run again, bit for bit, the scene a 'run --json' output recorded (its "
        "'inputs'); no scene, plate, sphere or model option with it",
    )
    parsers["crater"].add_argument("--csv", metavar="FILE", help="write lateral_mm,depth_mm here")
    parsers["crater"].add_argument("--png", metavar="FILE", help="draw the crater here")
    add_dpi_option(parsers["crater"])
    parsers["sweep"].add_argument("--csv", metavar="FILE", help="write CSV here (default: stdout)")


def _scene(args: argparse.Namespace) -> tuple[Scene, Any, str]:
    """The scene, simulation and plate label of run and crater."""
    scene_flags(args, "--speed", "--obliquity")
    choice = model_choice(args)
    simulation = choice.simulation()
    sphere, plate, label = bodies(args, choice, simulation.model)
    speed = IMPACT_SPEED.parse(args.speed)
    obliquity = IMPACT_OBLIQUITY.parse(args.obliquity)
    return Scene(sphere, plate, speed, obliquity), simulation, label


#: The options of ``run`` that --inputs leaves free: what to print and write.
_OUTPUT_OPTIONS = ("command", "command_function", "debug", "inputs", "json", "trajectory")


def _recorded_scene(args: argparse.Namespace) -> tuple[Scene, Simulation, str]:
    """The scene, simulation and label of ``run --inputs FILE``."""
    given = sorted(
        "--" + dest.replace("_", "-")
        for dest, value in vars(args).items()
        if dest not in _OUTPUT_OPTIONS and not dest.startswith("_") and value not in (None, [])
    )
    if given:
        raise UsageError(
            f"--inputs cannot be combined with {', '.join(given)}: the file gives the whole "
            "scene and model (edit a copy of it to change one)"
        )
    recorded = load_run_inputs(args.inputs, default_registry())
    return recorded.scene, recorded.simulation, recorded.label


def _user(declared: Parameter, scene: Scene) -> float:
    """A value of the scene in the user's unit, exact where a number there is."""
    value = getattr(scene, declared.name)
    exact = declared.user_number(value)
    return value / declared.scale if exact is None else exact


def run_command(args: argparse.Namespace) -> None:
    check_directory(args.trajectory, "--trajectory")
    check_directory(args.trajectory and sidecar(args.trajectory), "--trajectory", "json")
    if args.inputs is not None:
        scene, simulation, label = _recorded_scene(args)
    else:
        missing = [flag for flag in ("--speed", "--obliquity") if getattr(args, flag[2:]) is None]
        if missing:
            raise UsageError(
                f"the following arguments are required: {', '.join(missing)} (or --inputs)"
            )
        scene, simulation, label = _scene(args)
    result = simulation.run(scene, record_trajectory=args.trajectory is not None)
    speed, obliquity = (_user(d, scene) for d in (IMPACT_SPEED, IMPACT_OBLIQUITY))
    # the record (source commit, code hashes) only where it is written or printed
    inputs = None
    if args.json or args.trajectory is not None:
        inputs = inputs_record(
            simulation,
            scene.sphere,
            scene.plate,
            label=label,
            scene={IMPACT_SPEED: scene.impact_speed, IMPACT_OBLIQUITY: scene.impact_obliquity},
        )
    if args.trajectory is not None and result.trajectory is not None and inputs is not None:
        path = result.trajectory
        fields = list(TRAJECTORY_FIELDS.values())
        rows = zip(*(getattr(path, f.name) / f.scale for f in fields), strict=True)
        text = csv_text([f.key for f in fields], rows)
        # the path and, beside it, the run's inputs (run --inputs reads them): together
        write_together(csv_and_sidecar(args.trajectory, "--trajectory", [text], inputs))
    if args.json:
        out: dict[str, Any] = {
            "preset": label,
            IMPACT_SPEED.key: speed,
            IMPACT_OBLIQUITY.key: obliquity,
        }
        out.update(result.as_user_dict())
        out["model"] = simulation.describe()
        out["inputs"] = inputs
        say(json.dumps(out))
        return
    say(f"{shown(label, None)}: {speed:g} m/s at {obliquity:g} deg -> {result.outcome.label}")
    say(f"  exit speed       {result.exit_speed:.6g} m/s")
    say(f"  exit obliquity   {result.exit_obliquity_deg:.6g} deg")
    say(f"  contact time     {result.contact_time * 1e6:.6g} us")
    say(f"  max penetration  {result.max_penetration * 1e3:.6g} mm")
    if result.plate_failed:
        say(
            f"  plate failed     at P = {result.failure_penetration * 1e3:.6g} mm, "
            f"Y = {result.failure_lateral * 1e3:.6g} mm, t = {result.failure_time * 1e6:.6g} us"
        )
    else:
        say("  plate failed     no")


def crater_command(args: argparse.Namespace) -> None:
    check_directory(args.csv, "--csv")
    check_directory(args.png, "--png", "figure")
    scene, simulation, label = _scene(args)
    result = simulation.run(scene, record_trajectory=True)
    assert result.trajectory is not None
    section = crater_section(
        result.trajectory, scene.sphere.radius, thickness=scene.plate.thickness
    )
    say(
        f"{shown(label, None)}: {float(args.speed):g} m/s at {float(args.obliquity):g} deg -> "
        f"{result.outcome.label}; crater {section.length * 1e3:.4g} mm long, "
        f"{section.max_depth * 1e3:.4g} mm deep"
    )
    outputs = []  # the section and its figure land together
    if args.csv is not None:
        lateral, depth = CRATER_FIELDS["lateral"], CRATER_FIELDS["depth"]
        rows = zip(section.lateral / lateral.scale, section.depth / depth.scale, strict=True)
        outputs.append(text_output(args.csv, csv_text([lateral.key, depth.key], rows), "--csv"))
    if args.png is not None:
        from ..figures.crater_sections import plot_crater  # noqa: PLC0415 (matplotlib only when drawing)
        from ..figures.style import figure  # noqa: PLC0415

        fig, ax = figure(figsize=(8, 4))
        plot_crater(ax, section, trajectory=result.trajectory, radius=scene.sphere.radius)
        speed, obliquity = float(args.speed), float(args.obliquity)
        ax.set_title(f"{label}, {speed:g} m/s at {obliquity:g}°: {result.outcome.label}")
        outputs.append(figure_output(fig, args.png, "--png", args.dpi))
    write_together(outputs)


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


def sweep_command(args: argparse.Namespace) -> None:
    check_directory(args.csv, "--csv")
    check_directory(args.csv and sidecar(args.csv), "--csv", "json")
    scene_flags(args, "--speeds", "--obliquities")
    choice = model_choice(args)
    simulation = choice.simulation()
    sphere, plate, label = bodies(args, choice, simulation.model)
    speeds, obliquities = _parse_speeds(args.speeds), _parse_obliquities(args.obliquities)
    _check_sweep_size(speeds.size, obliquities.size, args.force)
    sweep = Sweep(simulation, sphere, plate, label, speeds, obliquities)
    texts = sweep.csv_chunks()  # the grid checked: nothing written yet
    with reporting_scenes("sweep", sweep.size):  # a bar on a terminal, after 2 s
        if args.csv is None:
            for text in texts:
                write_stdout(text)
            return
        record = sweep_inputs(args, simulation, sphere, plate, label)
        # the CSV and, beside it, what it holds: together, tied by the CSV's SHA-256
        write_together(csv_and_sidecar(args.csv, "--csv", texts, record))
    say(
        f"wrote {sweep.size} scenes to {shown(args.csv, None)}: "
        + ", ".join(f"{sweep.counts[o]} {o.label}" for o in Outcome)
    )
    say(f"inputs and provenance: {shown(sidecar(args.csv), None)}")
