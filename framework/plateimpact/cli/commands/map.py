"""``plateimpact map``: the outcome map of the (speed, obliquity) plane for one to four
plates, or the limit curves of several."""

from __future__ import annotations

import argparse
import copy
import json
import math
from typing import Any

import numpy as np

from ... import limits as lim
from ...limits.regimes import Regime
from ...model.results import RESULT_FIELDS
from ...model.scene import IMPACT_OBLIQUITY, IMPACT_SPEED
from ...registry.plugin_registry import PluginRegistry
from ...run.progress import reporting_scenes
from ...storage.together import write_together
from ..common import (
    UsageError,
    add_dpi_option,
    check_directory,
    csv_text,
    figure_output,
    text_output,
)
from ..formatting import shown, user
from ..limit_options import (
    add_archive_options,
    finite_number,
    step,
    store,
    values,
    writable_archive,
)
from ..options import add_body_options, add_model_options, bodies, model_choice, typed
from ..writer import Writer


def arguments(p: argparse.ArgumentParser, registry: PluginRegistry) -> None:
    p.add_argument(
        "--speeds", default="50:2000:200", help="START:STOP:N [m/s] (default 50:2000:200)"
    )
    p.add_argument(
        "--obliquities", default="0:85:86", help="START:STOP:N or a list [deg] (default 0:85:86)"
    )
    p.add_argument("--tolerance", default="0.01", help="boundaries to this [m/s] (default 0.01)")
    p.add_argument(
        "--kind",
        choices=("outcomes", "limits"),
        default="outcomes",
        help="outcomes: the plane coloured by outcome (one panel per --preset); limits: "
        "ballistic and ricochet limits against obliquity for every --preset",
    )
    p.add_argument("--png", metavar="FILE", help="draw here")
    p.add_argument("--csv", metavar="FILE",
                   help="write every cell of every map as CSV (one row per cell)")  # fmt: skip
    p.add_argument("--json", action="store_true", help="print one JSON object: every map")
    add_dpi_option(p)
    add_archive_options(p, "map_PRESET_FAILURE")
    add_body_options(p, registry, many_presets=True)
    add_model_options(p, registry)


def run(args: argparse.Namespace, registry: PluginRegistry, out: Writer) -> int:
    if args.png is None and args.csv is None and not args.json:
        raise UsageError("give --png FILE, --csv FILE or --json: what to make of the map")
    if args.kind == "limits" and args.png is None:
        raise UsageError("--kind limits is a figure: give --png FILE")
    check_directory(args.png, "--png", "figure")
    check_directory(args.csv, "--csv")
    archive = writable_archive(args)
    typed(args).update({"speeds": "--speeds", "impact_speed": "--speeds",
                        "obliquities": "--obliquities", "impact_obliquity": "--obliquities",
                        "tolerance": "--tolerance", "speed_samples": "--speeds"})  # fmt: skip
    parts = args.speeds.split(":")
    if len(parts) != 3:
        raise UsageError(f"--speeds must be START:STOP:N in m/s, got {args.speeds!r}")
    extent = (finite_number(parts[0], "--speeds"), finite_number(parts[1], "--speeds"))
    try:
        samples = int(parts[2])
    except ValueError:
        raise UsageError(f"--speeds: N must be an integer >= 2, got {parts[2]!r}") from None
    rows = values(args.obliquities, "--obliquities", "deg") * IMPACT_OBLIQUITY.scale
    tolerance = step(args.tolerance, "--tolerance")
    presets_given = args.preset or [None]
    if args.kind == "outcomes" and len(presets_given) > 4:
        raise UsageError("--preset: an outcome map draws at most 4 plates (one panel each)")
    choice = model_choice(args, registry)
    simulation = choice.simulation()
    plates = []
    for preset in presets_given:
        given = copy.copy(args)
        given.preset = preset
        plates.append(bodies(given, choice, simulation.model))
    spheres = {sphere for sphere, _, _ in plates}  # one, from --radius and --mass
    with reporting_scenes("map"):
        found = lim.outcome_maps(simulation, spheres.pop(), [plate for _, plate, _ in plates],
                                 extent, samples, rows, tolerance=tolerance)  # fmt: skip
    maps = [(label, one) for (_, _, label), one in zip(plates, found, strict=True)]
    shape, counted = found[0].shape, found[0].limits
    if not args.json:
        out.say(
            f"{', '.join(shown(label, None) for label, _ in maps)}: {len(maps)} map(s) of "
            f"{shape[0]} x {shape[1]}, {counted.scenes:,} scenes in {counted.seconds:.1f} s"
        )
    outputs = []  # the cells and the figure land together
    if args.csv is not None:
        outputs.append(text_output(args.csv, _csv(maps), "--csv"))
    if args.png is not None:
        from ...figures.limits_and_maps import plot_limit_curves, plot_outcome_map  # noqa: PLC0415

        draw = plot_limit_curves if args.kind == "limits" else plot_outcome_map
        outputs.append(figure_output(draw(maps), args.png, "--png", args.dpi))
    write_together(outputs)
    if args.json:
        out.say(json.dumps({"maps": [_json(label, one) for label, one in maps]}))
    elif args.png is not None:
        out.say(f"figure:  {args.png}")
    failure = simulation.model.failure.name
    for label, drawn in maps:
        name = f"map_{label}_{failure}"
        if args.name:
            name = args.name if len(maps) == 1 else f"{args.name}_{label}"
        store(archive, name, drawn, out)
    return 0


#: A cell's columns, in user units (as ``export`` names them).
CELL_COLUMNS = ("plate", "impact_obliquity_deg", "impact_speed_m_s", "outcome", "plate_failed",
                "exit_speed_m_s", "exit_obliquity_deg")  # fmt: skip


def _grid(found: lim.OutcomeMap) -> dict[str, list[list[Any]]]:
    """The map's cells row by row (obliquities) in user units, by the key ``--json``
    gives them: outcome, plate state, exit speed and exit obliquity (None where there is
    no number)."""

    def numbers(values: np.ndarray, declared: Any) -> list[list[float | None]]:
        return [[user(declared, v) if math.isfinite(v) else None for v in row] for row in values]

    regimes = [[Regime.of_code(int(c)) for c in row] for row in found.regime]
    return {
        "outcome": [[r.outcome.label for r in row] for row in regimes],
        "plate_failed": [[r.plate_failed for r in row] for row in regimes],
        "exit_speed_m_s": numbers(found.exit_speed, RESULT_FIELDS["exit_speed"]),
        "exit_obliquity_deg": numbers(found.exit_obliquity, RESULT_FIELDS["exit_obliquity"]),
    }


def _csv(maps: list[tuple[str, lim.OutcomeMap]]) -> str:
    """One row per cell of every map (obliquities outer, speeds inner); an empty field
    where there is no number."""
    rows = []
    for label, found in maps:
        cells = _grid(found)
        for i, obliquity in enumerate(found.obliquities):
            for j, speed in enumerate(found.speeds):
                row = [label, user(IMPACT_OBLIQUITY, obliquity), user(IMPACT_SPEED, speed)]
                row += [cells[key][i][j] for key in CELL_COLUMNS[3:]]
                rows.append(["" if v is None else v for v in row])
    return csv_text(CELL_COLUMNS, rows)


def _json(label: str, found: lim.OutcomeMap) -> dict[str, object]:
    """One map: its axes, its cells (:func:`_grid`), and the bands along each row as
    ``limits --json`` gives them."""
    return {
        "preset": label,
        "impact_speed_m_s": [user(IMPACT_SPEED, v) for v in found.speeds],
        "impact_obliquity_deg": [user(IMPACT_OBLIQUITY, v) for v in found.obliquities],
        **_grid(found),
        "limits": found.limits.to_json(),
    }
