"""``plateimpact v50``: V50 statistics of go/no-go shots (docs/experiment.md, "V50
statistics"), with the model's ballistic limit beside them when a plate is given."""

from __future__ import annotations

import argparse
import json
from collections.abc import Callable, Sequence
from pathlib import Path
from typing import Any

import numpy as np

from ... import limits as lim
from ...base.errors import V50Error
from ...model.bodies import Sphere
from ...model.scene import IMPACT_OBLIQUITY
from ...registry.plugin_registry import PluginRegistry
from ...run.progress import reporting_scenes
from ...storage.shots import Shots
from ...v50 import COUNTS, DEFAULT_SPREAD, METHODS, MilStd662F, V50Fit, fit_v50, mil_std_662f
from ...v50.fit import DEFAULT_BOOTSTRAP
from ...v50.likelihood import shown as count_shown
from ..common import UsageError, add_dpi_option, check_directory, save_figure_atomically
from ..formatting import interval, number, shown, user
from ..options import add_body_options, add_model_options, bodies, model_choice, typed
from ..writer import Writer

MIL_STD = "mil-std-662f"
#: Options of the fits, and of MIL-STD-662F: each refused with the other method.
FIT_OPTIONS = {"confidence": "--confidence", "bootstrap": "--bootstrap", "seed": "--seed"}
MIL_STD_OPTIONS = {"spread": "--spread", "count": "--count"}
#: Panels a figure draws at most.
MAX_PANELS = 16
#: Fits one command makes at most unless --force: each group's, and each of its
#: bootstrap resamples' (0.35 ms each for 30 shots on one core, loaded: 10**6 is about
#: six minutes).
MAX_FITS = 1_000_000
Estimate = V50Fit | MilStd662F


def arguments(p: argparse.ArgumentParser, registry: PluginRegistry) -> None:
    p.description = (
        "Estimate the V50 ballistic limit of go/no-go shots: a maximum-likelihood "
        "probit or logit fit of P(perforation) against impact speed, with V50, sigma, V10 and "
        "V90 and their profile-likelihood and bootstrap confidence intervals, or the "
        "MIL-STD-662F mean of the highest partial and lowest complete penetrations within a "
        "velocity span. With a plate (--preset, --plate-file or plate options) the model's "
        "ballistic limit at each obliquity is reported and drawn beside it."
    )
    p.add_argument(
        "shots",
        metavar="SHOTS.csv",
        help="columns impact_speed_m_s,impact_obliquity_deg and any of outcome, perforated, "
        "residual_speed_m_s (whether each shot perforated), weight, ...",
    )
    p.add_argument(
        "--method",
        choices=(*METHODS, MIL_STD),
        default=METHODS[0],
        help="probit (default), logit, or mil-std-662f",
    )
    p.add_argument(
        "--by-obliquity",
        action="store_true",
        help="one V50 per impact obliquity (shots at several obliquities need it)",
    )
    p.add_argument("--confidence", help="level of the intervals (default 0.95)")
    p.add_argument(
        "--bootstrap",
        metavar="N",
        help=f"bootstrap resamples, 0 for none (default {DEFAULT_BOOTSTRAP})",
    )
    p.add_argument("--seed", metavar="N", help="seed of the bootstrap (default 0)")
    p.add_argument(
        "--spread",
        metavar="M_S",
        help=f"mil-std-662f: the velocity span allowed [m/s] (default {DEFAULT_SPREAD:g}, "
        "125 ft/s)",
    )
    p.add_argument(
        "--count",
        metavar="N",
        help=f"mil-std-662f: partial and complete penetrations averaged, each "
        f"({', '.join(map(str, COUNTS))}; default the most within the span)",
    )
    p.add_argument("--json", action="store_true", help="print JSON: one object per group")
    p.add_argument(
        "--force",
        action="store_true",
        help=f"make more than {MAX_FITS:,} fits (groups x (1 + bootstrap resamples)), and "
        f"scan more than {lim.MAX_SCAN_SCENES:,} scenes for the model's ballistic limits",
    )
    p.add_argument(
        "--png",
        metavar="FILE",
        help="draw P(perforation) against impact speed: shots, fitted curve, V50 interval "
        "and the model's ballistic limit",
    )
    add_body_options(p, registry)
    add_model_options(p, registry)
    # The plate and model options, by destination: any of them asks for the model's
    # ballistic limit (and then for a plate), none is ignored.
    probe = argparse.ArgumentParser(add_help=False)
    add_body_options(probe, registry)
    add_model_options(probe, registry)
    model_options = sorted(vars(probe.parse_args([])))
    add_dpi_option(p)
    p.set_defaults(model_options=model_options)


def _number(text: str, flag: str, kind: type = float) -> Any:
    try:
        value = kind(text)
    except ValueError:
        noun = "a whole number" if kind is int else "a number"
        raise UsageError(f"{flag} must be {noun}, got {text!r}") from None
    return value


def _estimator(args: argparse.Namespace) -> Callable[..., Estimate]:
    """A function of (speed, perforated, weight, label) for --method and its options."""
    flags = typed(args)
    flags.update({**FIT_OPTIONS, **MIL_STD_OPTIONS})  # ParameterError names the flag
    wrong = MIL_STD_OPTIONS if args.method != MIL_STD else FIT_OPTIONS
    given = [flag for name, flag in wrong.items() if getattr(args, name) is not None]
    if given:
        raise UsageError(f"{', '.join(given)}: not an option of --method {args.method}")
    if args.method == MIL_STD:
        spread = DEFAULT_SPREAD if args.spread is None else _number(args.spread, "--spread")
        count = None if args.count is None else _number(args.count, "--count", int)
        return lambda v, y, w, label: mil_std_662f(
            v, y, w, spread_m_s=spread, count=count, label=label
        )
    options: dict[str, Any] = {"method": args.method}
    if args.confidence is not None:
        options["confidence"] = _number(args.confidence, "--confidence")
    if args.bootstrap is not None:
        options["bootstrap"] = _number(args.bootstrap, "--bootstrap", int)
    if args.seed is not None:
        seed = _number(args.seed, "--seed", int)
        if seed < 0:
            raise UsageError(f"--seed must be a whole number >= 0, got {args.seed!r}")
        options["rng"] = seed
    return lambda v, y, w, label: fit_v50(v, y, w, label=label, **options)


def _groups(args: argparse.Namespace, shots: Shots) -> dict[float, Shots]:
    groups = shots.groups_by_obliquity()
    if len(groups) > 1 and not args.by_obliquity:
        angles = ", ".join(number(IMPACT_OBLIQUITY, o) for o in groups)
        raise UsageError(
            f"{args.shots}: shots at {len(groups)} obliquities ({angles} deg): a V50 is of "
            "one obliquity; give --by-obliquity for one V50 each"
        )
    if args.png is not None and len(groups) > MAX_PANELS:
        raise UsageError(f"--png: shots at {len(groups)} obliquities; the figure draws at most "
                         f"{MAX_PANELS}")  # fmt: skip
    return groups


def _check_fits(args: argparse.Namespace, groups: int) -> None:
    """Refuse, before any work, more fits than MAX_FITS unless --force."""
    if args.method == MIL_STD or args.force:
        return
    resamples = (
        DEFAULT_BOOTSTRAP if args.bootstrap is None else _number(args.bootstrap, "--bootstrap", int)
    )
    fits = groups * (1 + max(resamples, 0))
    if fits > MAX_FITS:
        raise UsageError(
            f"--bootstrap {resamples} at {groups} obliquities makes {fits:,} fits, more than "
            f"{MAX_FITS:,}: ask for fewer resamples, or give --force"
        )


def _model_limits(
    args: argparse.Namespace, groups: dict[float, Shots], registry: PluginRegistry
) -> tuple[dict[float, float | None], str | None]:
    """The model's ballistic limit [m/s] at each group's obliquity, when a plate or model
    option was given (None where the model has none in the speeds searched)."""
    if not any(getattr(args, name) not in (None, []) for name in args.model_options):
        return {}, None
    choice = model_choice(args, registry)
    simulation = choice.simulation()
    sphere, plate, label = bodies(args, choice, simulation.model)
    by_sphere: dict[Sphere, list[float]] = {}
    for obliquity, group in groups.items():
        radius, mass = group.spheres(sphere)
        if np.ptp(radius) > 0 or np.ptp(mass) > 0:
            raise UsageError(
                f"{args.shots} at {number(IMPACT_OBLIQUITY, obliquity)} deg: the shots give "
                "different spheres (radius_mm, mass_g); the model's ballistic limit is of "
                "one sphere: give shots of one sphere per obliquity"
            )
        by_sphere.setdefault(Sphere(float(radius[0]), float(mass[0])), []).append(obliquity)
    speeds = np.concatenate([g.impact_speed for g in groups.values()])
    # the limits command's speeds, and the shots' with half their speed either side
    span = (min(lim.SPEED_RANGE[0], 0.5 * speeds.min()),
            max(lim.SPEED_RANGE[1], 1.5 * speeds.max()))  # fmt: skip
    found: dict[float, float | None] = {}
    with reporting_scenes("v50"):
        for one, obliquities in by_sphere.items():
            limits = lim.along_speed(
                simulation, one, plate, obliquities, span,
                max_scenes=None if args.force else lim.MAX_SCAN_SCENES,
            )  # fmt: skip
            lines = zip(obliquities, limits.lines, strict=True)
            found.update({o: line.ballistic_limit for o, line in lines})
    failure = simulation.model.failure.name
    return found, f"{label}, {simulation.model.resistance.name} + {failure}"


def run(args: argparse.Namespace, registry: PluginRegistry, out: Writer) -> int:
    """Run ``plateimpact v50``."""
    check_directory(args.png, "--png", "figure")
    estimate = _estimator(args)
    shots = Shots.from_csv(args.shots)
    groups = _groups(args, shots)
    _check_fits(args, len(groups))
    model_limits, model = _model_limits(args, groups, registry)
    results: dict[float, Estimate | str] = {}
    for obliquity, group in groups.items():
        label = f"{args.shots} at {number(IMPACT_OBLIQUITY, obliquity)} deg"
        try:
            results[obliquity] = estimate(group.impact_speed, group.perforated, group.weight, label)
        except V50Error as exc:
            if len(groups) == 1:
                raise
            results[obliquity] = str(exc).removeprefix(f"{label}: ")
    if all(isinstance(r, str) for r in results.values()):
        reasons = "; ".join(f"{number(IMPACT_OBLIQUITY, o)} deg: {r}" for o, r in results.items())
        raise V50Error(f"{args.shots}: no obliquity gives a V50; {reasons}")
    if args.png is not None:
        from ...figures.v50_fits import Panel, v50_figure  # noqa: PLC0415 (matplotlib only when drawing)

        panels = [
            Panel(f"{number(IMPACT_OBLIQUITY, o)} deg", groups[o].impact_speed,
                  groups[o].perforated, groups[o].weight, r, model_limits.get(o))
            for o, r in results.items()
        ]  # fmt: skip
        # the file's name, not the path it was given by (relative to somewhere else)
        figure = v50_figure(panels, title=Path(args.shots).name, model=model)
        save_figure_atomically(figure, args.png, dpi=args.dpi)
    rows = [_json(args, o, r, groups[o].labels, model_limits, model) for o, r in results.items()]
    if args.json:
        out.say(json.dumps(rows[0] if len(rows) == 1 else rows))
    else:
        for row in rows:
            out.say(_text(row))
        if args.png is not None:
            out.say(f"figure: {args.png}")
    return 0


def _json(
    args: argparse.Namespace, obliquity: float, result: Estimate | str, labels: Sequence[str],
    model_limits: dict[float, float | None], model: str | None,
) -> dict[str, Any]:  # fmt: skip
    # 30, not 29.999999999999996 after the round trip through rad
    degrees = float(f"{user(IMPACT_OBLIQUITY, obliquity):.12g}")
    row: dict[str, Any] = {"shots_file": args.shots, "obliquity_deg": degrees}
    if isinstance(result, str):
        row.update({"method": args.method, "error": result})
    elif isinstance(result, MilStd662F):
        # the keys every method has; MIL-STD-662F gives no curve, so no sigma, V10, V90
        none = dict.fromkeys(("sigma_m_s", "v50_ci_m_s", "v10_m_s", "v90_m_s"))
        row.update({**none, **result.to_json()})
        row["used"] = [labels[i] for i in result.used]  # the file's lines, not indices
    else:
        row.update(result.to_json())
    if model is not None:
        row["model"] = model
        row["model_ballistic_limit_m_s"] = model_limits[obliquity]
    return row


def _text(row: dict[str, Any]) -> str:
    where = f"{shown(row['shots_file'], None)} at {row['obliquity_deg']:g} deg"
    if "error" in row:
        lines = [f"{where}: no V50: {shown(row['error'], None)}"]
    elif row["method"] == MIL_STD:
        partial = ", ".join(f"{v:g}" for v in row["partial_speeds_m_s"])
        complete = ", ".join(f"{v:g}" for v in row["complete_speeds_m_s"])
        lines = [
            f"{where}: MIL-STD-662F V50 {row['v50_m_s']:.4g} m/s from {row['rounds']} of "
            f"{row['shots']} rounds, spanning {row['spread_m_s']:.3g} m/s (at most "
            f"{row['spread_allowed_m_s']:.3g} allowed)",
            f"  highest partial penetrations {partial} m/s; lowest complete {complete} m/s",
        ]
    else:
        resamples = row["bootstrap_resamples"]
        # shots are rounds (weights counted); the rows too when a row stands for several
        rows = f" ({row['rows']} rows)" if row["rows"] != row["rounds"] else ""
        lines = [
            f"{where}: {count_shown(row['rounds'])} shots{rows}, "
            f"{count_shown(row['perforations'])} perforated; {row['method']} fit, "
            f"{100 * row['confidence']:g}% intervals: profile likelihood"
            + (f" | bootstrap ({resamples} resamples)" if resamples else "")
        ]
        for name, key in (("V50", "v50"), ("sigma", "sigma"), ("V10", "v10"), ("V90", "v90")):
            boot = f"  {interval(row[f'{key}_bootstrap_ci_m_s'])}" if resamples else ""
            profile = interval(row[f"{key}_ci_m_s"])
            lines.append(f"  {name:6s}{row[f'{key}_m_s']:9.4g} m/s  {profile}{boot}")
        low, high = row["mixed_zone_m_s"]
        note = f"zone of mixed results {low:g}-{high:g} m/s"
        kinds = (("bootstrap_separated", "separated (sigma 0)"),
                 ("bootstrap_flat", "flat (no rise with speed)"),
                 ("bootstrap_failed", "failed (no fit converged: left out)"))  # fmt: skip
        if resamples:  # said even when 0: a reader need not guess
            note += "; of the resamples " + ", ".join(f"{row[k]} {what}" for k, what in kinds)
        lines.append(f"  {note}")
    if "model" in row:
        limit = row["model_ballistic_limit_m_s"]
        limit_text = "none in the speeds searched" if limit is None else f"{limit:.2f} m/s"
        lines.append(f"  model ({shown(row['model'], None)}): ballistic limit {limit_text}")
    return "\n".join(lines)
