"""``plateimpact calibrate``, the report's: a and b from shots at normal incidence (eqs
40–49), or with ``--fit pstar`` P* and α* from oblique shots (:mod:`.calibrate_pstar_command`).

The core's ``calibrate`` command hands its parser and arguments to the registered
``calibrate`` procedure: this module (:func:`arguments`, :func:`run`)."""

from __future__ import annotations

import argparse
import json
import math
import os
from typing import TYPE_CHECKING, Any, TypeAlias

import numpy as np

from plateimpact import Plate, PluginRegistry, Shots, Simulation, Sphere, calibration, units
from plateimpact import command_line as cli

from .calibrate_pstar_command import add_pstar_options, pstar_command, refuse_pstar_options
from .constants import DENSITY_B, STRENGTH_A

g, mm = units.g, units.mm
#: The largest fit run unasked [scenes] (the core's bound; a name here for tests to lower).
MAX_FIT_SCENES = calibration.MAX_FIT_SCENES

if TYPE_CHECKING:
    from matplotlib.figure import Figure

#: The registered calibration procedure's results (a plug-in package's classes).
Calibration: TypeAlias = Any
CalibrationReport: TypeAlias = Any
#: Model-curve points on the figure.
CURVE_POINTS = 150


def arguments(p: argparse.ArgumentParser, registry: PluginRegistry) -> None:
    p.description = (
        "Fit the Poncelet constants a and b to shots at normal incidence: the "
        "DRI fit (eqs 40-41), the report's Newton iteration (eqs 44-49) and a direct "
        "least-squares fit; P* and alpha* are given (from craters, as in the report). "
        "With --fit pstar: a and b given, fit P* (and alpha*) to the outcomes and "
        "residual speeds of oblique shots by maximum likelihood, or with --by-obliquity "
        "the report's variable P*."
    )
    p.add_argument(
        "shots",
        metavar="SHOTS.csv",
        help="columns impact_speed_m_s,impact_obliquity_deg and any of outcome, perforated, "
        "residual_speed_m_s (0: no perforation), exit_obliquity_deg, radius_mm, mass_g, "
        "weight, source",
    )
    p.add_argument(
        "--fit",
        choices=("ab", "pstar"),
        default="ab",
        help="what to fit: ab (default: a and b at normal incidence) or pstar (P*, and "
        "alpha* with --alpha-fit, from oblique shots)",
    )
    p.add_argument("--material", default="calibrated", help="material label of the plate")
    p.add_argument(
        "--method",
        choices=("newton", "direct"),
        help="--fit ab: whose a, b are headlined and written to --out (default: newton, the "
        "report's)",
    )
    p.add_argument(
        "--out",
        metavar="FILE",
        help="write the calibrated plate file (JSON) here; with --by-obliquity the P* table (CSV)",
    )
    p.add_argument("--png", metavar="FILE", help="draw data, DRI curve and model curves here")
    cli.add_dpi_option(p)
    p.add_argument("--json", action="store_true", help="print one JSON object")
    p.add_argument(
        "--force",
        action="store_true",
        help=f"run a fit estimated at more than {MAX_FIT_SCENES:,} scenes (refused unasked, "
        "before any scene runs)",
    )
    add_pstar_options(p)
    cli.add_body_options(p, registry)
    cli.add_model_options(p, registry)


def run(args: argparse.Namespace, registry: PluginRegistry, out: cli.Writer) -> int:
    """Run ``plateimpact calibrate``."""
    if args.fit == "pstar":
        pstar_command(args, registry, out)
        return 0
    refuse_pstar_options(args)
    args.method = args.method or "newton"
    cli.check_directory(args.out, "--out")
    cli.check_directory(args.png, "--png", "figure")
    shots = Shots.from_csv(args.shots)
    choice = cli.model_choice(args, registry)
    simulation = choice.simulation()
    # a and b are what the calibration finds: placeholders until then.
    choice.plate.setdefault("a", 1.0)
    choice.plate.setdefault("b", 1.0)
    sphere, given, _ = cli.bodies(args, choice, simulation.model)
    plate = Plate(args.material, given.thickness, given.constants)
    with cli.reporting_scenes("calibrate"):  # a count of scenes on a terminal after 2 s
        # the registered calibration procedure: the report's, from its plug-in package
        report = choice.registry.procedure("calibration").calibrate(
            shots, plate, sphere=sphere, simulation=simulation,
            max_scenes=None if args.force else MAX_FIT_SCENES,
        )  # fmt: skip
    chosen = report.newton if args.method == "newton" else report.direct
    summary = _summary(args, report, chosen)
    summary["model"] = simulation.describe()
    outputs = []  # the plate file and the figure of its fit land together
    if args.out is not None:
        provenance = _provenance(args, report, chosen, sphere)
        extra = {"calibration": {**provenance, "model": summary["model"]}}
        text = cli.plate_file_text(chosen.plate, extra, registry=registry)
        outputs.append(cli.text_output(args.out, text, "--out"))
    if args.png is not None:
        figure = _figure(report, sphere, simulation)
        outputs.append(cli.figure_output(figure, args.png, "--png", args.dpi))
    cli.write_together(outputs)
    if args.json:
        out.say(json.dumps(summary))
    else:
        _print_text(args, report, chosen, out)
    return 0


def _finite(x: float) -> float | None:
    """``x``, or None (JSON null) where it is NaN: a standard error with no residual left."""
    return x if math.isfinite(x) else None


def _method_dict(fit: Calibration) -> dict[str, Any]:
    return {
        "a_N_m2": fit.a,
        "a_stderr_N_m2": _finite(fit.a_stderr),
        "b_kg_m3": fit.b,
        "b_stderr_kg_m3": _finite(fit.b_stderr),
        "correlation": fit.correlation,
        "iterations": fit.iterations,
        "converged": fit.converged,
        "model_R": fit.model_fit.R,
        "model_V0_m_s": fit.model_fit.V0,
        "rms_residual_m_s": fit.rms_residual,
    }


def _summary(
    args: argparse.Namespace, report: CalibrationReport, chosen: Calibration
) -> dict[str, Any]:
    normal = report.shots.normal_incidence()
    return {
        "shots_file": args.shots,
        "shots": len(report.shots),
        "normal_incidence_shots": len(normal),
        "perforating_shots": int(normal.perforated.sum()),
        "method": chosen.method,
        "a_N_m2": chosen.a,
        "a_stderr_N_m2": _finite(chosen.a_stderr),
        "b_kg_m3": chosen.b,
        "b_stderr_kg_m3": _finite(chosen.b_stderr),
        # of the errors of a and b: with the standard errors, their covariance
        "ab_correlation": _finite(chosen.correlation),
        # the same, as plateimpact uncertainty reads it from this file ("calibration_file")
        "uncertainty": _uncertainty(chosen),
        "R": report.dri.R,
        "R_stderr": report.dri.R_stderr,
        "V0_m_s": report.dri.V0,
        "V0_stderr_m_s": report.dri.V0_stderr,
        "dri_rms_residual_m_s": report.dri.rms_residual,
        "newton": _method_dict(report.newton),
        "direct": _method_dict(report.direct),
        "plate_file": args.out,
    }


def _provenance(
    args: argparse.Namespace, report: CalibrationReport, chosen: Calibration, sphere: Sphere
) -> dict[str, Any]:
    return {
        "method": chosen.method,
        "shots_file": os.path.basename(args.shots),
        "a_stderr_N_m2": _finite(chosen.a_stderr),
        "b_stderr_kg_m3": _finite(chosen.b_stderr),
        # of the errors of a and b: with the standard errors, their covariance
        "ab_correlation": _finite(chosen.correlation),
        # the same, as plateimpact uncertainty reads it from this file ("calibration_file")
        "uncertainty": _uncertainty(chosen),
        "R": report.dri.R,
        "V0_m_s": report.dri.V0,
        "sphere": {"radius_mm": sphere.radius / mm, "mass_g": sphere.mass / g},
        "plateimpact_version": cli.versions()["plateimpact"],
    }


def _uncertainty(chosen: Calibration) -> dict[str, Any] | None:
    """The fit's a and b as an uncertainty spec's inputs and correlation: normal, with
    their standard errors and the correlation of their errors (None without them)."""
    numbers = (chosen.a_stderr, chosen.b_stderr, chosen.correlation)
    if not all(math.isfinite(x) for x in numbers) or min(numbers[:2]) <= 0:
        return None
    a_key, b_key = STRENGTH_A.key, DENSITY_B.key
    return {
        "inputs": {
            a_key: {"normal": {"mean": chosen.a, "sd": chosen.a_stderr}},
            b_key: {"normal": {"mean": chosen.b, "sd": chosen.b_stderr}},
        },
        "correlations": [[a_key, b_key, chosen.correlation]],
    }


def _print_text(
    args: argparse.Namespace, report: CalibrationReport, chosen: Calibration, out: cli.Writer
) -> None:
    normal = report.shots.normal_incidence()
    ignored = len(report.shots) - len(normal)
    dri = report.dri
    out.say(
        f"shots: {args.shots}: {len(normal)} at normal incidence, "
        f"{int(normal.perforated.sum())} perforating"
        + (f" ({ignored} oblique shots not used)" if ignored else "")
    )
    out.say(
        f"DRI fit (eqs 40-41): R = {dri.R:.5g} ± {dri.R_stderr:.2g}, "
        f"V0 = {dri.V0:.5g} ± {dri.V0_stderr:.2g} m/s, rms residual {dri.rms_residual:.3g} m/s"
    )
    out.say(
        f"{'':22s}{'a [N/m^2]':>22s}{'b [kg/m^3]':>20s}{'steps':>7s}"
        f"{'model R':>10s}{'model V0':>10s}{'rms [m/s]':>10s}"
    )
    for name, fit in (
        ("newton (eqs 44-49)", report.newton),
        ("direct least squares", report.direct),
    ):
        out.say(
            f"{name:22s}{f'{fit.a:.5g} ± {fit.a_stderr:.2g}':>22s}"
            f"{f'{fit.b:.5g} ± {fit.b_stderr:.2g}':>20s}{fit.iterations:7d}"
            f"{fit.model_fit.R:10.5g}{fit.model_fit.V0:10.5g}{fit.rms_residual:10.3g}"
        )
    newton, direct = report.newton, report.direct
    out.say(
        f"direct - newton: a {100 * (direct.a / newton.a - 1):+.3g} %, "
        f"b {100 * (direct.b / newton.b - 1):+.3g} % "
        f"({abs(direct.a - newton.a) / newton.a_stderr:.2g} and "
        f"{abs(direct.b - newton.b) / newton.b_stderr:.2g} standard errors of newton)"
    )
    out.say(f"plate ({chosen.method}): a = {chosen.a:.6g} N/m^2, b = {chosen.b:.6g} kg/m^3")
    if args.out is not None:
        out.say(f"plate file: {args.out}")
    if args.png is not None:
        out.say(f"figure: {args.png}")


def _figure(report: CalibrationReport, sphere: Sphere, simulation: Simulation) -> Figure:
    """Residual speed against impact speed: shots, DRI fit, model curves of both fits."""

    normal = report.shots.normal_incidence()
    speeds = np.linspace(
        0.8 * normal.impact_speed.min(), 1.05 * normal.impact_speed.max(), CURVE_POINTS
    )
    fits = (report.newton, report.direct)
    curves = calibration.model_residual_speeds(
        simulation, sphere, fits[0].plate, speeds, [{"a": f.a, "b": f.b} for f in fits]
    )
    fig, ax = cli.figure(figsize=(7, 5))
    cli.plot_calibration(
        ax,
        normal,
        report.dri,
        {
            f"model, {fit.method}: a = {fit.a:.3g} N/m², b = {fit.b:.3g} kg/m³": (speeds, curve)
            for fit, curve in zip(fits, curves, strict=True)
        },
    )
    plate = fits[0].plate
    ax.set_title(
        f"{plate.material}, T = {plate.thickness / mm:g} mm, P* = "
        f"{plate.critical_penetration / mm:g} mm: residual speed at normal incidence"
    )
    return fig
