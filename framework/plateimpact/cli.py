"""The ``plateimpact`` command: user units (mm, m/s, g, degrees) in and out.

Every input error prints one line, ``plateimpact: error: ...``, and exits with code 2.
"""

from __future__ import annotations

import argparse
import csv
import io
import json
import math
import os
import sys
import tempfile
from collections.abc import Sequence
from typing import Any, NoReturn

import attrs
import numpy as np

from . import presets
from .archive import Archive
from .batch import SceneBatch
from .bodies import Plate, Sphere
from .errors import ParameterError, PlateImpactError
from .plate_file import load_plate_file
from .results import BatchResult, Outcome
from .scene import Scene
from .simulation import DEFAULT_FAILURE, DEFAULT_INTEGRATOR, DEFAULT_RESISTANCE, Simulation
from .units import deg, g, mm

#: Which flag carries which parameter, so that an error names what the user typed.
FLAG_OF = {
    "impact_speed": "--speed",
    "impact_obliquity": "--obliquity",
    "thickness": "--thickness",
    "a": "--a",
    "b": "--b",
    "critical_penetration": "--pstar",
    "failure_angle": "--alpha",
    "radius": "--radius",
    "mass": "--mass",
    "step": "--step",
    "rtol": "--rtol",
}

SWEEP_COLUMNS = (
    "preset",
    "impact_speed_m_s",
    "impact_obliquity_deg",
    "outcome",
    "exit_speed_m_s",
    "exit_obliquity_deg",
    "contact_time_s",
    "max_penetration_mm",
    "plate_failed",
)


class UsageError(PlateImpactError):
    """A command-line argument is malformed."""


class _Parser(argparse.ArgumentParser):
    def error(self, message: str) -> NoReturn:  # one line, exit 2, no usage dump
        self.exit(2, f"plateimpact: error: {message}\n")


def _add_model_options(parser: argparse.ArgumentParser) -> None:
    group = parser.add_argument_group("model (plug-ins by name; see 'plateimpact plugins')")
    group.add_argument("--resistance", default=DEFAULT_RESISTANCE, help="resistance law")
    group.add_argument("--failure", default=DEFAULT_FAILURE, help="failure model")
    group.add_argument("--integrator", default=DEFAULT_INTEGRATOR, help="integrator")
    group.add_argument(
        "--pstar-table",
        metavar="FILE",
        help="CSV of P* by obliquity and speed, for --failure variable-pstar "
        "(columns obliquity_deg,ricochet_pstar_mm,perforation_pstar_mm,"
        "transition_start_m_s,transition_end_m_s)",
    )
    group.add_argument(
        "--step",
        type=float,
        help="for --integrator segment: the segment duration as a fraction of Rs/Vs "
        "(default 1e-3, finest documented 1e-4)",
    )
    group.add_argument(
        "--rtol",
        type=float,
        help="for adaptive integrators (dopri5, solve_ivp): relative tolerance "
        "(dopri5 default 1e-10)",
    )


def _add_body_options(parser: argparse.ArgumentParser) -> None:
    group = parser.add_argument_group("plate and sphere (override the preset)")
    group.add_argument("--preset", help=f"plate preset: {', '.join(presets.PLATES)}")
    group.add_argument(
        "--plate-file",
        metavar="FILE",
        help="plate from a plate file (JSON, e.g. written by 'plateimpact calibrate --out'); "
        "not with --preset or the plate options",
    )
    group.add_argument("--thickness", type=float, help="plate thickness T [mm]")
    group.add_argument("--a", type=float, help="Poncelet strength term a [N/m^2]")
    group.add_argument("--b", type=float, help="Poncelet inertial term b [kg/m^3]")
    group.add_argument("--pstar", type=float, help="critical penetration P* [mm] (inf: never)")
    group.add_argument("--alpha", type=float, help="failure angle alpha* [deg]")
    group.add_argument("--radius", type=float, help="sphere radius Rs [mm] (default 3.175)")
    group.add_argument("--mass", type=float, help="sphere mass m [g] (default 1.0498)")


def build_parser() -> argparse.ArgumentParser:
    """The argument parser of the ``plateimpact`` command."""
    parser = _Parser(prog="plateimpact", description=__doc__.splitlines()[0])
    sub = parser.add_subparsers(dest="command", required=True, parser_class=_Parser)

    p = sub.add_parser("presets", help="list the plate presets and the default sphere")
    p.add_argument("--json", action="store_true", help="print JSON")

    sub.add_parser("plugins", help="list the installed plug-ins by kind")

    p = sub.add_parser("run", help="run one scene")
    p.add_argument("--speed", type=float, required=True, help="impact speed [m/s]")
    p.add_argument("--obliquity", type=float, required=True, help="impact obliquity [deg]")
    p.add_argument("--json", action="store_true", help="print one JSON object")
    p.add_argument("--trajectory", metavar="FILE", help="write the trajectory as CSV")
    _add_body_options(p)
    _add_model_options(p)

    p = sub.add_parser("crater", help="the crater section of one scene (eqs 31-39)")
    p.add_argument("--speed", type=float, required=True, help="impact speed [m/s]")
    p.add_argument("--obliquity", type=float, required=True, help="impact obliquity [deg]")
    p.add_argument("--csv", metavar="FILE", help="write lateral_mm,depth_mm here")
    p.add_argument("--png", metavar="FILE", help="draw the crater here")
    _add_body_options(p)
    _add_model_options(p)

    p = sub.add_parser("sweep", help="run a grid of speeds and obliquities")
    p.add_argument(
        "--speeds", required=True, help="impact speeds [m/s]: START:STOP:N or a comma list"
    )
    p.add_argument("--obliquities", required=True, help="impact obliquities [deg], a comma list")
    p.add_argument("--csv", metavar="FILE", help="write CSV here (default: standard output)")
    _add_body_options(p)
    _add_model_options(p)

    from .cli_calibrate import add_calibrate_parser  # noqa: PLC0415 (it imports this module)

    add_calibrate_parser(sub)

    p = sub.add_parser("reproduce", help="run the report's figure families into one archive")
    p.add_argument("--out", default="report", help="output directory, created (default: report)")
    p.add_argument(
        "--resume",
        action="store_true",
        help="keep the runs already in DIR/report.h5 and run only the missing ones "
        "(default: add every run again, as NAME.2, ...)",
    )

    p = sub.add_parser("show", help="list an archive's runs, their metadata and a summary")
    p.add_argument("archive", help="HDF5 archive")

    p = sub.add_parser("compare", help="compare two runs of an archive scene by scene")
    p.add_argument("archive", help="HDF5 archive")
    p.add_argument("run_a", help="run name (STUDY/RUN, or RUN when unique)")
    p.add_argument("run_b", help="run name (STUDY/RUN, or RUN when unique)")
    p.add_argument("--png", metavar="FILE", help="overlay plot of the two runs")

    p = sub.add_parser(
        "plot", help="exit curves, trajectories or crater sections of runs in an archive"
    )
    p.add_argument("archive", help="HDF5 archive")
    p.add_argument("--run", required=True, action="append", help="run name (repeat to overlay)")
    p.add_argument("--out", required=True, metavar="FILE.png", help="where to draw")
    p.add_argument(
        "--kind",
        choices=("exit", "trajectory", "crater"),
        default="exit",
        help="exit speed and obliquity against impact speed (default); the centre's "
        "trajectories; crater sections (runs recorded with trajectories / craters)",
    )
    p.add_argument(
        "--speed",
        type=float,
        action="append",
        metavar="M_S",
        help="trajectory/crater: draw the scene nearest this impact speed (repeat; "
        "default: six spread over the range)",
    )
    return parser


def _bodies(args: argparse.Namespace) -> tuple[Sphere, Plate, str]:
    plate_flags = ("thickness", "a", "b", "pstar", "alpha")
    if args.plate_file is not None:
        given = ["--preset"] * (args.preset is not None)
        given += [f"--{f}" for f in plate_flags if getattr(args, f) is not None]
        if given:
            raise UsageError(f"--plate-file cannot be combined with {', '.join(given)}")
        base, label = load_plate_file(args.plate_file), os.path.basename(args.plate_file)
    elif args.preset is None:
        missing = [f"--{f}" for f in plate_flags if getattr(args, f) is None]
        if missing:
            raise UsageError(
                "--preset is required unless all plate options are given "
                f"(missing {', '.join(missing)})"
            )
        base, label = None, "custom"
    else:
        base, label = presets.plate(args.preset), args.preset
    overrides: dict[str, Any] = {}
    for flag, field, unit in (
        ("thickness", "thickness", mm),
        ("a", "a", 1.0),
        ("b", "b", 1.0),
        ("pstar", "critical_penetration", mm),
        ("alpha", "failure_angle", deg),
    ):
        if getattr(args, flag) is not None:
            overrides[field] = getattr(args, flag) * unit
    if base is None:
        plate = Plate(material="custom", **overrides)
    else:
        plate = attrs.evolve(base, **overrides) if overrides else base
        if overrides:
            label = f"{label}+custom"
    return _sphere(args), plate, label


def _sphere(args: argparse.Namespace) -> Sphere:
    """The default sphere, or the one of --radius [mm] and --mass [g]."""
    sphere = presets.DEFAULT_SPHERE
    if args.radius is not None or args.mass is not None:
        radius = args.radius * mm if args.radius is not None else sphere.radius
        if args.mass is not None:
            sphere = Sphere(radius=radius, mass=args.mass * g)
        else:  # a new radius keeps the default sphere's density
            sphere = Sphere.of_density(radius, presets.SAE_52100_DENSITY)
    return sphere


def _simulation(args: argparse.Namespace) -> Simulation:
    settings = {} if args.step is None else {"step": args.step}
    if args.rtol is not None:
        settings["rtol"] = args.rtol
    failure_settings = {} if args.pstar_table is None else {"table": args.pstar_table}
    return Simulation.from_names(
        args.resistance,
        args.failure,
        args.integrator,
        integrator_settings=settings,
        failure_settings=failure_settings,
    )


def _parse_speeds(text: str) -> np.ndarray:
    try:
        if ":" in text:
            start, stop, count = text.split(":")
            n = int(count)
            if n < 1:
                raise ValueError
            return np.linspace(float(start), float(stop), n)
        return np.array([float(x) for x in text.split(",")])
    except ValueError:
        raise UsageError(
            f"--speeds must be START:STOP:N (N >= 1) or a comma list in m/s, got {text!r}"
        ) from None


def _parse_obliquities(text: str) -> np.ndarray:
    try:
        return np.array([float(x) for x in text.split(",")])
    except ValueError:
        raise UsageError(f"--obliquities must be a comma list in degrees, got {text!r}") from None


def _check_directory(path: str | None, flag: str) -> None:
    """Refuse an output path in a missing directory before any work is done."""
    if path is not None and not os.path.isdir(os.path.dirname(os.path.abspath(path))):
        raise UsageError(
            f"{flag}: directory {os.path.dirname(os.path.abspath(path))!r} does not exist"
        )


def _write_atomically(path: str, text: str, flag: str) -> None:
    """Write ``text`` to ``path`` so that no partial file is ever left behind."""
    _check_directory(path, flag)
    directory = os.path.dirname(os.path.abspath(path))
    fd, tmp = tempfile.mkstemp(dir=directory, prefix=".plateimpact-", suffix=".tmp")
    try:
        with os.fdopen(fd, "w", newline="") as handle:
            handle.write(text)
        os.replace(tmp, path)
    except BaseException:
        if os.path.exists(tmp):
            os.unlink(tmp)
        raise


def _save_figure_atomically(fig: Any, path: str) -> None:
    """Save a matplotlib figure to ``path`` [PNG] so that no partial file is left behind."""
    from . import plotting

    directory = os.path.dirname(os.path.abspath(path))
    fd, tmp = tempfile.mkstemp(dir=directory, prefix=".plateimpact-", suffix=".png")
    os.close(fd)
    try:
        plotting.save(fig, tmp)
        os.replace(tmp, path)
    finally:
        if os.path.exists(tmp):
            os.unlink(tmp)


def _cmd_presets(args: argparse.Namespace) -> None:
    sphere = presets.DEFAULT_SPHERE
    rows = {
        name: {
            "material": p.material,
            "thickness_mm": p.thickness / mm,
            "pstar_mm": p.critical_penetration / mm,
            "alpha_deg": round(p.failure_angle / deg, 9),
            "a_N_m2": p.a,
            "b_kg_m3": p.b,
        }
        for name, p in presets.PLATES.items()
    }
    sphere_row = {
        "material": "SAE 52100",
        "radius_mm": sphere.radius / mm,
        "mass_g": sphere.mass / g,
        "density_kg_m3": presets.SAE_52100_DENSITY,
    }
    if args.json:
        print(json.dumps({"plates": rows, "sphere": sphere_row}, indent=2))
        return
    print(
        f"{'plate':14s} {'material':9s} {'T mm':>6s} {'P* mm':>6s} {'a* deg':>6s} "
        f"{'a N/m^2':>10s} {'b kg/m^3':>9s}"
    )
    for name, r in rows.items():
        print(
            f"{name:14s} {r['material']:9s} {r['thickness_mm']:6.2f} {r['pstar_mm']:6.2f} "
            f"{r['alpha_deg']:6.1f} {r['a_N_m2']:10.4g} {r['b_kg_m3']:9.4g}"
        )
    print(
        f"\nsphere (default): SAE 52100, radius {sphere_row['radius_mm']:.4g} mm, "
        f"mass {sphere_row['mass_g']:.4f} g, density {sphere_row['density_kg_m3']:.0f} kg/m^3"
    )


def _cmd_plugins(args: argparse.Namespace) -> None:
    from .registry import KINDS, default_registry

    registry = default_registry()
    for kind in KINDS:
        print(f"{kind}: {', '.join(registry.names(kind))}")


def _cmd_run(args: argparse.Namespace) -> None:
    _check_directory(args.trajectory, "--trajectory")
    sphere, plate, label = _bodies(args)
    scene = Scene(sphere, plate, args.speed, args.obliquity * deg)
    simulation = _simulation(args)
    result = simulation.run(scene, record_trajectory=args.trajectory is not None)
    if args.trajectory is not None:
        t = result.trajectory
        buffer = io.StringIO()
        writer = csv.writer(buffer, lineterminator="\n")
        writer.writerow(["time_s", "penetration_mm", "lateral_mm", "obliquity_deg", "speed_m_s"])
        for row in zip(
            t.time, t.penetration / mm, t.lateral / mm, t.obliquity / deg, t.speed, strict=True
        ):
            writer.writerow([repr(float(x)) for x in row])
        _write_atomically(args.trajectory, buffer.getvalue(), "--trajectory")
    out = {"preset": label, "impact_speed_m_s": args.speed, "impact_obliquity_deg": args.obliquity}
    out.update(result.as_user_dict())
    out["model"] = simulation.describe()
    if args.json:
        print(json.dumps(out))
        return
    print(f"{label}: {args.speed:g} m/s at {args.obliquity:g} deg -> {result.outcome.label}")
    print(f"  exit speed       {result.exit_speed:.6g} m/s")
    print(f"  exit obliquity   {result.exit_obliquity_deg:.6g} deg")
    print(f"  contact time     {result.contact_time * 1e6:.6g} us")
    print(f"  max penetration  {result.max_penetration / mm:.6g} mm")
    if result.plate_failed:
        print(
            f"  plate failed     at P = {result.failure_penetration / mm:.6g} mm, "
            f"Y = {result.failure_lateral / mm:.6g} mm, t = {result.failure_time * 1e6:.6g} us"
        )
    else:
        print("  plate failed     no")


def _cmd_crater(args: argparse.Namespace) -> None:
    from .crater import crater_section

    _check_directory(args.csv, "--csv")
    _check_directory(args.png, "--png")
    sphere, plate, label = _bodies(args)
    scene = Scene(sphere, plate, args.speed, args.obliquity * deg)
    result = _simulation(args).run(scene, record_trajectory=True)
    section = crater_section(result.trajectory, sphere.radius, thickness=plate.thickness)
    print(
        f"{label}: {args.speed:g} m/s at {args.obliquity:g} deg -> {result.outcome.label}; "
        f"crater {section.length / mm:.4g} mm long, {section.max_depth / mm:.4g} mm deep"
    )
    if args.csv is not None:
        buffer = io.StringIO()
        writer = csv.writer(buffer, lineterminator="\n")
        writer.writerow(["lateral_mm", "depth_mm"])
        for y, x in zip(section.lateral / mm, section.depth / mm, strict=True):
            writer.writerow([repr(float(y)), repr(float(x))])
        _write_atomically(args.csv, buffer.getvalue(), "--csv")
    if args.png is not None:
        from . import plotting

        fig, ax = plotting.plt.subplots(figsize=(8, 4))
        plotting.plot_crater(ax, section, trajectory=result.trajectory, radius=sphere.radius)
        ax.set_title(f"{label}, {args.speed:g} m/s at {args.obliquity:g}°: {result.outcome.label}")
        _save_figure_atomically(fig, args.png)


def _cmd_sweep(args: argparse.Namespace) -> None:
    _check_directory(args.csv, "--csv")
    sphere, plate, label = _bodies(args)
    speeds, obliquities = _parse_speeds(args.speeds), _parse_obliquities(args.obliquities)
    batch = SceneBatch.grid(sphere, plate, speeds, obliquities * deg)
    result = _simulation(args).run_batch(batch)
    # Echo the values as typed (the grid is obliquity-major), not their round trip via SI.
    typed_obliquity = np.repeat(obliquities, speeds.size)
    typed_speed = np.tile(speeds, obliquities.size)
    buffer = io.StringIO()
    writer = csv.writer(buffer, lineterminator="\n")
    writer.writerow(SWEEP_COLUMNS)
    for i in range(len(result)):
        writer.writerow(
            [
                label,
                repr(float(typed_speed[i])),
                repr(float(typed_obliquity[i])),
                Outcome(int(result.outcome[i])).label,
                repr(float(result.exit_speed[i])),
                repr(float(result.exit_obliquity[i] / deg)),
                repr(float(result.contact_time[i])),
                repr(float(result.max_penetration[i] / mm)),
                str(bool(result.plate_failed[i])).lower(),
            ]
        )
    if args.csv is None:
        sys.stdout.write(buffer.getvalue())
    else:
        _write_atomically(args.csv, buffer.getvalue(), "--csv")
        counts = np.bincount(result.outcome, minlength=4)
        print(
            f"wrote {len(result)} scenes to {args.csv}: "
            + ", ".join(f"{counts[o]} {o.label}" for o in Outcome)
        )


def _cmd_calibrate(args: argparse.Namespace) -> None:
    from .cli_calibrate import calibrate_command  # noqa: PLC0415 (it imports this module)

    calibrate_command(args)


COMMANDS = {
    "presets": _cmd_presets,
    "plugins": _cmd_plugins,
    "run": _cmd_run,
    "crater": _cmd_crater,
    "sweep": _cmd_sweep,
    "calibrate": _cmd_calibrate,
}


def _cmd_reproduce(args: argparse.Namespace) -> None:
    from pathlib import Path  # noqa: PLC0415

    try:
        from plateimpact_studies.reproduce import reproduce  # noqa: PLC0415
    except ImportError:
        raise UsageError(
            "the report studies (package plateimpact_studies) are not installed"
        ) from None
    out = Path(args.out)
    if not out.parent.resolve().is_dir():
        raise UsageError(f"--out: directory {str(out.parent)!r} does not exist")
    archive, figures = reproduce(out, resume=args.resume)
    print(f"archive: {archive}")
    for figure in figures:
        print(f"figure:  {figure}")


def _run_results(archive: Archive, run: str) -> tuple[str, BatchResult]:
    name = archive.resolve(run)
    return name, archive.results(name)


def _cmd_show(args: argparse.Namespace) -> None:
    archive = Archive(args.archive)
    for name in archive.runs():
        meta = archive.metadata(name)
        result = archive.results(name)
        variant = meta["variant"]
        counts = np.bincount(result.outcome, minlength=4)[1:]
        print(f"{name}")
        print(
            f"  model: {variant['resistance']} + {variant['failure']}, "
            f"integrator {variant['integrator']} {meta['model']['integrator_settings']}"
        )
        print(
            f"  {len(result)} scenes: {counts[0]} ricochet, {counts[1]} embedment, "
            f"{counts[2]} perforation; wall {meta['wall_time_s']:.2f} s"
        )
        kept = [
            what
            for what, data in (("trajectories", result.trajectory), ("craters", result.craters))
            if data is not None
        ]
        if kept:
            print(f"  with {' and '.join(kept)}")
        print(
            f"  run {meta['start_time']} on {meta['host']}, plateimpact "
            f"{meta['versions'].get('plateimpact')}, commit {meta['git_commit'][:12]}"
        )


def _cmd_compare(args: argparse.Namespace) -> None:
    from .study import StudyResults  # noqa: PLC0415

    _check_directory(args.png, "--png")
    archive = Archive(args.archive)
    name_a, name_b = archive.resolve(args.run_a), archive.resolve(args.run_b)
    (_, result_a), (_, result_b) = _run_results(archive, name_a), _run_results(archive, name_b)
    study_a, study_b = name_a.split("/", 1)[0], name_b.split("/", 1)[0]
    if study_a != study_b:
        raise UsageError(f"runs {name_a} and {name_b} belong to different studies")
    study = archive.study(study_a)
    results = StudyResults(study, {name_a: result_a, name_b: result_b})
    comparison = results.compare(name_a, name_b)
    scenes = study.scenes
    print(f"{name_b} against {name_a}: {len(result_a)} scenes")
    for i in comparison.changed:
        print(
            f"  {study.plate_labels[i]:>14} {np.degrees(scenes.impact_obliquity[i]):5.1f} deg "
            f"{scenes.impact_speed[i]:7.1f} m/s: {Outcome(comparison.outcome_a[i]).label} -> "
            f"{Outcome(comparison.outcome_b[i]).label}"
        )
    print(json.dumps(comparison.summary(), indent=2))
    if args.png:
        from . import plotting  # noqa: PLC0415

        plotting.save(plotting.plot_study(results), args.png)


def _cmd_plot(args: argparse.Namespace) -> None:
    from . import plotting  # noqa: PLC0415
    from .study import StudyResults  # noqa: PLC0415

    _check_directory(args.out, "--out")
    for speed in args.speed or ():
        if not (math.isfinite(speed) and speed > 0.0):
            raise UsageError(f"--speed must be a finite impact speed > 0 m/s, got {speed}")
    archive = Archive(args.archive)
    runs = dict(_run_results(archive, run) for run in args.run)
    studies = {name.split("/", 1)[0] for name in runs}
    if len(studies) != 1:
        raise UsageError(f"--run: runs of one study only, got {', '.join(sorted(runs))}")
    results = StudyResults(archive.study(studies.pop()), runs)
    if args.kind == "exit":
        figure = plotting.plot_study(results)
    else:
        try:
            figure = plotting.plot_study_paths(results, kind=args.kind, speeds=args.speed)
        except ValueError as exc:
            raise UsageError(str(exc)) from None
    plotting.save(figure, args.out)
    print(f"figure: {args.out}")


COMMANDS.update(reproduce=_cmd_reproduce, show=_cmd_show, compare=_cmd_compare, plot=_cmd_plot)


def main(argv: Sequence[str] | None = None) -> int:
    """Entry point of the ``plateimpact`` command; returns the exit code."""
    args = build_parser().parse_args(argv)
    try:
        COMMANDS[args.command](args)
    except ParameterError as exc:
        flag = FLAG_OF.get(exc.parameter)
        prefix = f"{flag}: " if flag else ""
        print(f"plateimpact: error: {prefix}{exc}", file=sys.stderr)
        return 2
    except PlateImpactError as exc:
        print(f"plateimpact: error: {exc}", file=sys.stderr)
        return 2
    except BrokenPipeError:  # e.g. piped into head
        sys.stderr.close()
        return 0
    return 0


if __name__ == "__main__":
    sys.exit(main())
