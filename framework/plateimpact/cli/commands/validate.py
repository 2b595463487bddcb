"""``plateimpact validate``: the model against measured shots (docs/experiment.md)."""

from __future__ import annotations

import argparse
import json

import numpy as np

from ...experiment import MEASURED, PREDICTED, ValidationReport, validate
from ...experiment.validation import MAX_VALIDATE_SCENES
from ...model.scene import IMPACT_OBLIQUITY
from ...registry.plugin_registry import PluginRegistry
from ...run.progress import reporting_scenes
from ...storage.shots import Shots
from ..common import add_dpi_option, check_directory, save_figure_atomically
from ..formatting import ANGLE, number, quantity, shown
from ..options import add_body_options, add_model_options, bodies, model_choice
from ..writer import Writer

#: Disagreeing shots listed in the text output (--json lists all).
LISTED = 10


def arguments(p: argparse.ArgumentParser, registry: PluginRegistry) -> None:
    p.description = (
        "Run the model on every shot of SHOTS.csv and compare: the confusion "
        "matrix of outcomes (measured -> predicted; go/no-go shots perforated or not), the "
        "weighted agreement, the residual-speed error (RMS and bias, model minus measured) "
        "and exit-obliquity error (RMS) where shot and model both leave the plate the same "
        "way, and each disagreeing shot with its distance along impact speed to the nearest "
        "boundary of the model beyond which it gives what was measured."
    )
    p.add_argument(
        "shots",
        metavar="SHOTS.csv",
        help="columns impact_speed_m_s,impact_obliquity_deg and any of outcome, perforated, "
        "residual_speed_m_s, exit_obliquity_deg, radius_mm, mass_g, weight, source",
    )
    p.add_argument("--json", action="store_true", help="print one JSON object")
    p.add_argument(
        "--force",
        action="store_true",
        help=f"run more than {MAX_VALIDATE_SCENES:,} scenes (the shots and, should shots on "
        "every line disagree, the boundary search; refused unasked before any scene runs)",
    )
    p.add_argument(
        "--png",
        metavar="FILE",
        help="draw each obliquity's exit speed and obliquity, the model's curves and "
        "bands, and the shots",
    )
    add_body_options(p, registry)
    add_model_options(p, registry)
    add_dpi_option(p)


def run(args: argparse.Namespace, registry: PluginRegistry, out: Writer) -> int:
    """Run ``plateimpact validate``."""
    check_directory(args.png, "--png", "figure")
    shots = Shots.from_csv(args.shots)
    if args.png is not None:
        from ...figures.validation_panels import check_panels  # noqa: PLC0415 (matplotlib)

        check_panels(shots)
    choice = model_choice(args, registry)
    simulation = choice.simulation()
    sphere, plate, label = bodies(args, choice, simulation.model)
    with reporting_scenes("validate"):  # a count of scenes on a terminal after 2 s
        bound = None if args.force else MAX_VALIDATE_SCENES
        report = validate(simulation, sphere, plate, shots, max_scenes=bound)
        if args.png is not None:
            from ...figures.validation_panels import validation_figure  # noqa: PLC0415 (matplotlib)

            figure = validation_figure(report, simulation, title=label)
    if args.png is not None:
        save_figure_atomically(figure, args.png, dpi=args.dpi)
    if args.json:
        out.say(json.dumps({"shots_file": args.shots, "plate_label": label, **report.to_json()}))
    else:
        _print_text(args, label, report, out)
    return 0


def _print_text(
    args: argparse.Namespace, label: str, report: ValidationReport, out: Writer
) -> None:
    shots = report.shots
    model = report.model
    go_no_go = int((shots.outcome == 0).sum())
    obliquities = np.unique(shots.impact_obliquity)  # a file may measure each shot's
    angles = ", ".join(number(IMPACT_OBLIQUITY, o) for o in obliquities[:LISTED])
    if obliquities.size > LISTED:
        angles += f", ... ({obliquities.size:,} obliquities)"
    out.say(
        f"{shown(label, None)}: {len(shots)} shots from {shown(args.shots, None)}"
        + (f" ({go_no_go} go/no-go)" if go_no_go else "")
        + f" at {angles} deg; model {shown(model['resistance'])} + {shown(model['failure'])} "
        f"({shown(model['integrator'])})"
    )
    out.say(f"outcome agreement {100 * report.agreement:.1f}% (weighted)")
    width = max(len(name) for name in MEASURED) + 2
    out.say(f"  {'measured -> model':{width}s}" + "".join(f"{p:>13s}" for p in PREDICTED))
    for name in MEASURED:
        counts = report.confusion[name]
        if any(counts.values()):
            out.say(f"  {name:{width}s}" + "".join(f"{counts[p]:13d}" for p in PREDICTED))
    pairs = int(np.isfinite(report.residual_speed_error).sum())
    if pairs:
        out.say(
            f"residual speed, model - measured: rms {report.residual_speed_rms:.3g} m/s, "
            f"bias {report.residual_speed_bias:+.3g} m/s over {pairs} shots"
        )
    else:
        out.say("residual speed: no shot where shot and model leave the plate the same way")
    pairs = int(np.isfinite(report.exit_obliquity_error).sum())
    if pairs:
        rms = quantity(ANGLE, report.exit_obliquity_rms, 3)
        out.say(f"exit obliquity, model - measured: rms {rms} over {pairs} shots")
    wrong = report.disagreements
    if wrong:
        out.say(f"{len(wrong)} shots disagree (distance to the nearest speed the model agrees at):")
    for d in wrong[:LISTED]:
        where = (
            f"{d.distance:.3g} m/s from the boundary at {d.boundary:.2f} m/s"
            if d.distance is not None
            else f"no boundary in {report.speeds[0]:g}-{report.speeds[1]:g} m/s"
        )
        line = d.label.removeprefix(f"{args.shots} ")  # the file is named above
        angle = quantity(IMPACT_OBLIQUITY, d.impact_obliquity)
        out.say(
            f"  {shown(line, None)}: {d.impact_speed:g} m/s at {angle}, measured "
            f"{d.measured}, model {d.predicted}; {where}"
        )
    if len(wrong) > LISTED:
        out.say(f"  ... and {len(wrong) - LISTED} more (--json lists all)")
    if args.png is not None:
        out.say(f"figure: {args.png}")
