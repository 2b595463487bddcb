"""``plateimpact calibrate --fit pstar``: P* (and α*) from oblique shots, a and b fixed
(docs/calibration.md, "P* and α* from oblique shots")."""

from __future__ import annotations

import argparse
import json
import math
import os
from typing import Any, TypeAlias

from plateimpact import Plate, PluginRegistry, Shots, Simulation, Sphere, calibration, limits, units
from plateimpact import command_line as cli

g, mm = units.g, units.mm
#: The largest fit run unasked [scenes] (the core's bound; a name here for tests to lower).
MAX_FIT_SCENES = calibration.MAX_FIT_SCENES

#: The fits, and their search's constants, are the registered calibration procedure's
#: (``registry.procedure("calibration")``, a plug-in package's): PstarFit, PstarTableFit
#: and PstarEstimate are its classes.
PstarFit: TypeAlias = Any
PstarTableFit: TypeAlias = Any
PstarEstimate: TypeAlias = Any


#: The options only --fit pstar reads, with their defaults (a typed one is refused with
#: --fit ab rather than ignored).
PSTAR_OPTIONS = {
    "--by-obliquity": ("by_obliquity", False),
    "--alpha-fit": ("alpha_fit", False),
    "--speed-sigma": ("speed_sigma", None),
    "--residual-sigma": ("residual_sigma", None),
    "--resolution": ("resolution", None),
    "--tolerance": ("tolerance", None),
}


def add_pstar_options(p: argparse.ArgumentParser) -> None:
    """The options of ``calibrate --fit pstar``."""
    group = p.add_argument_group("--fit pstar (P* and alpha* from oblique shots; a, b fixed)")
    group.add_argument(
        "--by-obliquity",
        action="store_true",
        help="fit a ricochet-range and a perforation-range P* at each obliquity (the "
        "report's variable P*); --out writes the variable-pstar table (CSV)",
    )
    group.add_argument(
        "--alpha-fit", action="store_true", help="fit alpha* too (--alpha is its start)"
    )
    group.add_argument(
        "--speed-sigma",
        type=float,
        metavar="M_S",
        help=f"impact-speed scatter s of the outcome probability, (0, 1000] m/s "
        f"(default {calibration.SPEED_SIGMA:g})",
    )
    group.add_argument(
        "--residual-sigma",
        type=float,
        metavar="M_S",
        help="residual-speed scatter sigma_r, (0, 1000] m/s (default: fitted)",
    )
    group.add_argument(
        "--resolution",
        type=float,
        metavar="M_S",
        help=f"boundary finder: no band this wide missed (default {limits.SPEED_RESOLUTION:g} m/s)",
    )
    group.add_argument(
        "--tolerance",
        type=float,
        metavar="M_S",
        help=f"boundary finder: boundaries to this (default {limits.SPEED_TOLERANCE:g} m/s)",
    )


def refuse_pstar_options(args: argparse.Namespace) -> None:
    """With --fit ab, a typed --fit pstar option is an error, not ignored."""
    for flag, (dest, default) in PSTAR_OPTIONS.items():
        if getattr(args, dest) != default:
            raise cli.UsageError(f"{flag}: only with --fit pstar")


def pstar_command(args: argparse.Namespace, registry: PluginRegistry, out: cli.Writer) -> None:
    """Run ``plateimpact calibrate --fit pstar``."""
    for flag in ("--method", "--png"):
        if getattr(args, flag.lstrip("-")) is not None:
            raise cli.UsageError(f"{flag}: only with --fit ab")
    if args.by_obliquity and args.alpha_fit:
        raise cli.UsageError(
            "--alpha-fit: not with --by-obliquity (the variable-pstar table holds P* only; "
            "fit alpha* first without --by-obliquity)"
        )
    cli.check_directory(args.out, "--out")
    shots = Shots.from_csv(args.shots)
    choice = cli.model_choice(args, registry)
    fits = registry.procedure("calibration")  # the report's, from its plug-in package
    simulation = choice.simulation()
    if getattr(args, "pstar", None) is not None or "critical_penetration" in choice.plate:
        flag = choice.plate_flags.get("critical_penetration", "--pstar")
        raise cli.UsageError(
            f"{flag}: not with --fit pstar (P* is what it fits, over a fixed range; see "
            "docs/calibration.md)"
        )
    if args.preset is None and args.plate_file is None:
        given = {n for n in ("a", "b") if getattr(args, n, None) is not None or n in choice.plate}
        if given != {"a", "b"}:
            raise cli.UsageError(
                "--fit pstar holds a and b fixed: give --preset, --plate-file, or --a and --b "
                "(fit them first with --fit ab)"
            )
        choice.plate.setdefault("critical_penetration", mm)  # what the fit finds
    sphere, given_plate, _ = cli.bodies(args, choice, simulation.model)
    plate = Plate(args.material, given_plate.thickness, given_plate.constants)
    cli.typed(args).update({"speed_sigma": "--speed-sigma", "residual_sigma": "--residual-sigma"})
    model = calibration.ProbabilityModel(
        calibration.SPEED_SIGMA if args.speed_sigma is None else args.speed_sigma,
        args.residual_sigma,
    )
    finder = {
        "resolution": limits.SPEED_RESOLUTION if args.resolution is None else args.resolution,
        "tolerance": limits.SPEED_TOLERANCE if args.tolerance is None else args.tolerance,
    }
    cli.typed(args).update({"tolerance": "--tolerance", "resolution": "--resolution"})
    calibration.check_finder(**finder)
    bound = None if args.force else MAX_FIT_SCENES
    with cli.reporting_scenes("calibrate"):  # a count of scenes on a terminal after 2 s
        if args.by_obliquity:
            table = fits.fit_pstar_by_obliquity(
                shots, plate, sphere=sphere, simulation=simulation, model=model,
                resolution=finder["resolution"], tolerance=finder["tolerance"],
                max_scenes=bound,
            )  # fmt: skip
        else:
            fit = fits.fit_pstar(
                shots, plate, sphere=sphere, simulation=simulation, model=model,
                fit_alpha=args.alpha_fit, resolution=finder["resolution"],
                tolerance=finder["tolerance"], max_scenes=bound,
            )  # fmt: skip
    if args.by_obliquity:
        summary = _table_summary(fits, args, table, simulation, finder, sphere)
        if args.out is not None:
            cli.write_atomically(args.out, table.csv_text(), "--out")
        out.say(json.dumps(summary) if args.json else _table_text(args, table))
        return
    summary = _fit_summary(fits, args, fit, simulation, finder, sphere)
    if args.out is not None:
        extra = {"calibration": _provenance(args, fit, sphere, summary)}
        cli.write_atomically(
            args.out, cli.plate_file_text(fit.plate, extra, registry=registry), "--out"
        )
    out.say(json.dumps(summary) if args.json else _fit_text(fits, args, fit))


def _finite(x: float) -> float | None:
    return x if math.isfinite(x) else None


def _probability_model(
    args: argparse.Namespace, model: calibration.ProbabilityModel, sigma: float
) -> dict[str, Any]:
    return {
        "description": "P(outcome | v) = normal mass of the model's outcome bands about the "
        "measured impact speed v with standard deviation s, mixed with a blunder "
        "probability; residual speed ~ normal about the model's mean residual speed over "
        "the perforating impact speeds, variance sigma_r^2 + its variance there",
        "speed_sigma_m_s": model.speed_sigma,
        "speed_sigma_given": args.speed_sigma is not None,
        "residual_sigma_m_s": _finite(sigma),
        "residual_sigma_fitted": model.residual_sigma is None,
        "outcome_blunder": calibration.OUTCOME_BLUNDER,
    }


def _search(
    fits: Any, finder: dict[str, float], cost: calibration.Cost, sphere_radius: float
) -> dict[str, Any]:
    return {
        "pstar_range_mm": [r * sphere_radius / mm for r in fits.PSTAR_RANGE],
        "scan_points": fits.SCAN_POINTS,
        "information_step_ln_pstar": fits.PSTAR_STEP,
        "resolution_m_s": finder["resolution"],
        "tolerance_m_s": finder["tolerance"],
        "evaluations": cost.evaluations,
        "batches": cost.batches,
        "seconds": round(cost.seconds, 3),
    }


def _fit_summary(
    fits: Any,
    args: argparse.Namespace,
    fit: PstarFit,
    simulation: Simulation,
    finder: dict[str, float],
    sphere: Sphere,
) -> dict[str, Any]:
    e = fit.estimate
    out: dict[str, Any] = {
        "fit": "pstar",
        "shots_file": args.shots,
        "shots": fit.shots,
        "residual_speed_shots": fit.residual_shots,
        "pstar_mm": e.pstar / mm,
        "pstar_mm_stderr": e.pstar_stderr / mm,
        "alpha_deg": cli.user(cli.ANGLE, e.alpha),
        "alpha_fitted": fit.alpha_fitted,
    }
    if fit.alpha_fitted:
        out["alpha_deg_stderr"] = cli.user(cli.ANGLE, e.alpha_stderr)
        out["pstar_alpha_correlation"] = e.correlation
    return out | {
        "log_likelihood": e.log_likelihood,
        "converged": True,  # a fit that does not converge is an error (exit code 2)
        "shots_near_boundary": e.near,
        "near_boundary_speed_sigmas": fits.NEAR,
        "probability_model": _probability_model(args, fit.model, e.residual_sigma),
        "search": _search(fits, finder, fit.cost, sphere.radius),
        "note": fit.note or None,
        "plate_file": args.out,
        "model": simulation.describe(),
    }


def _provenance(
    args: argparse.Namespace, fit: PstarFit, sphere: Sphere, summary: dict[str, Any]
) -> dict[str, Any]:
    keep = ("pstar_mm_stderr", "alpha_fitted", "alpha_deg_stderr", "log_likelihood", "shots")
    return {
        "method": "pstar maximum likelihood (docs/calibration.md)",
        "shots_file": os.path.basename(args.shots),
        **{key: summary[key] for key in keep if key in summary},
        "probability_model": summary["probability_model"],
        "sphere": {"radius_mm": sphere.radius / mm, "mass_g": sphere.mass / g},
        "plateimpact_version": cli.versions()["plateimpact"],
        "model": summary["model"],
    }


def _fit_text(fits: Any, args: argparse.Namespace, fit: PstarFit) -> str:
    e = fit.estimate
    model = fit.model
    if math.isnan(e.residual_sigma):
        sigma = "no residual speeds"
    elif model.residual_sigma is not None:
        sigma = f"sigma_r = {e.residual_sigma:.3g} m/s (given)"
    elif e.residual_sigma <= 1.001 * calibration.RESIDUAL_SIGMA_BOUNDS[0]:
        sigma = (
            f"sigma_r = {e.residual_sigma:.3g} m/s (fitted, its lower bound: the impact-speed "
            "scatter accounts for the residual scatter)"
        )
    else:
        sigma = f"sigma_r = {e.residual_sigma:.3g} m/s (fitted)"
    alpha = (
        f"alpha* = {cli.user(cli.ANGLE, e.alpha):.4g} "
        f"± {cli.user(cli.ANGLE, e.alpha_stderr):.2g} deg "
        f"(correlation with P* {e.correlation:+.2f})"
        if fit.alpha_fitted
        else f"alpha* = {cli.user(cli.ANGLE, e.alpha):.4g} deg (given)"
    )
    lines = [
        f"shots: {args.shots}: {fit.shots} used, {fit.residual_shots} with a residual speed",
        f"probability model: impact-speed scatter s = {model.speed_sigma:g} m/s"
        + (" (given)" if args.speed_sigma is not None else " (default)")
        + f", {sigma}, blunder {calibration.OUTCOME_BLUNDER:g}",
        f"P* = {e.pstar / mm:.5g} ± {e.pstar_stderr / mm:.2g} mm, {alpha}",
        f"log-likelihood {e.log_likelihood:.6g}; {e.near} shots within {fits.NEAR:g} s of a "
        f"boundary; {fit.cost.evaluations} candidates in {fit.cost.batches} batches, "
        f"{fit.cost.seconds:.1f} s",
    ]
    if fit.note:
        lines.append(f"note: {fit.note}")
    if args.out is not None:
        lines.append(f"plate file: {args.out}")
    return "\n".join(lines)


def _estimate_json(prefix: str, e: PstarEstimate, shots: int) -> dict[str, Any]:
    return {
        f"{prefix}_pstar_mm": e.pstar / mm,
        f"{prefix}_pstar_mm_stderr": _finite(e.pstar_stderr / mm),
        f"{prefix}_identified": e.identified,
        f"{prefix}_shots": shots,
        f"{prefix}_log_likelihood": _finite(e.log_likelihood) if e.identified else None,
        f"{prefix}_residual_sigma_m_s": _finite(e.residual_sigma) if e.identified else None,
    }


def _table_summary(
    fits: Any,
    args: argparse.Namespace,
    table: PstarTableFit,
    simulation: Simulation,
    finder: dict[str, float],
    sphere: Sphere,
) -> dict[str, Any]:
    rows = [
        {
            "obliquity_deg": float(f"{cli.user(cli.ANGLE, row.obliquity):.12g}"),  # 60, not 59.99..
            **_estimate_json("ricochet", row.ricochet, row.ricochet_shots),
            **_estimate_json("perforation", row.perforation, row.perforation_shots),
            "transition_start_m_s": row.transition_start,
            "transition_end_m_s": row.transition_end,
            "notes": list(row.notes),
        }
        for row in table.rows
    ]
    return {
        "fit": "pstar",
        "by_obliquity": True,
        "shots_file": args.shots,
        "alpha_deg": cli.user(cli.ANGLE, table.alpha),
        "rows": rows,
        "probability_model": _probability_model(args, table.model, math.nan)
        | {"residual_sigma_m_s": None},
        "search": _search(fits, finder, table.cost, sphere.radius),
        "table_file": args.out,
        "model": simulation.describe(),
    }


def _table_text(args: argparse.Namespace, table: PstarTableFit) -> str:
    def value(e: PstarEstimate) -> str:
        if not e.identified:
            return f"{e.pstar / mm:.4g} (not fitted)"
        return f"{e.pstar / mm:.4g} ± {e.pstar_stderr / mm:.2g}"

    lines = [
        f"P* by obliquity from {args.shots} (alpha* = {cli.user(cli.ANGLE, table.alpha):.4g} deg, "
        f"impact-speed scatter s = {table.model.speed_sigma:g} m/s)",
        f"{'obliquity':>9s}  {'ricochet P* [mm]':>22s}{'shots':>6s}  "
        f"{'perforation P* [mm]':>22s}{'shots':>6s}  band [m/s]",
    ]
    notes = []
    for row in table.rows:
        degrees = f"{cli.user(cli.ANGLE, row.obliquity):.6g}"
        lines.append(
            f"{degrees:>9s}  {value(row.ricochet):>22s}{row.ricochet_shots:6d}  "
            f"{value(row.perforation):>22s}{row.perforation_shots:6d}  "
            f"{row.transition_start:.1f}-{row.transition_end:.1f}"
        )
        notes += [f"{degrees} deg: {note}" for note in row.notes]
    lines += [f"note: {note}" for note in notes]
    cost = table.cost
    lines.append(f"{cost.evaluations} candidates in {cost.batches} batches, {cost.seconds:.1f} s")
    if args.out is not None:
        lines.append(f"table: {args.out} (--failure variable-pstar --pstar-table {args.out})")
    return "\n".join(lines)
