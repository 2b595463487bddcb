"""``plateimpact uncertainty --limits``: the ballistic and ricochet limits of every sample
at each obliquity, their V10/V50/V90 and sigma reported as ``plateimpact v50`` reports a
fit's (the same words and keys), optionally beside go/no-go shots (``--shots``, read and
fitted as ``v50`` does) and drawn as velocity-response curves (``--png``)."""

from __future__ import annotations

import argparse
import json
from typing import Any

import attrs
import numpy as np

from ..base.errors import V50Error
from ..model.bodies import MASS, RADIUS
from ..model.scene import IMPACT_OBLIQUITY
from ..run.progress import reporting_scenes
from ..run.simulation import Simulation
from ..storage.shots import Shots
from ..uncertainty.kept import kept_limits
from ..uncertainty.limits import OUTSIDE
from ..uncertainty.spec import UncertaintySpec, UncertaintySpecError
from ..v50 import V50Fit, fit_v50
from .common import UsageError, save_figure_atomically
from .formatting import interval, number, shown, user
from .limit_options import values
from .uncertainty_modes import (
    archive_of,
    figure_provenance,
    plate_title,
    provenance,
    stored,
)
from .writer import Writer

#: How the text names each limit, and what its samples outside the range mean.
NAMES = {"ballistic": "ballistic limit", "ricochet": "ricochet limit"}
MEANING = {
    "perforates_at_every_speed": "perforate at every speed of the range",
    "perforates_at_no_speed": "perforate at no speed of the range",
    "ricochets_at_no_speed": "ricochet at no speed of the range",
    "ricochets_at_every_speed": "ricochet at every speed of the range",
}
#: The same, said of every sample.
ALL = {
    "perforates_at_every_speed": "every sample perforates at every speed of it",
    "perforates_at_no_speed": "no sample perforates at any speed of it",
    "ricochets_at_no_speed": "no sample ricochets at any speed of it",
    "ricochets_at_every_speed": "every sample ricochets at every speed of it",
}


def obliquities(spec: UncertaintySpec, args: argparse.Namespace) -> np.ndarray:
    """The obliquities of the limits [deg]: --obliquities, else the spec's at."""
    if args.speeds is not None:
        raise UsageError(
            "--speeds: not with --limits (the sampled limits give P(perforation | V) at every "
            "speed: --png draws it)"
        )
    if "obliquity_deg" in spec.inputs:
        raise UncertaintySpecError(
            f"{spec.source}: obliquity_deg: --limits finds limits at given obliquities: give it "
            "in at or --obliquities, without a distribution"
        )
    if args.obliquities is not None:
        return values(args.obliquities, "--obliquities", "deg")
    return np.array([spec.at["obliquity_deg"]])


def _shots(
    args: argparse.Namespace, spec: UncertaintySpec, angles: np.ndarray, sphere: Any
) -> dict[int, Any]:
    """The --shots at each obliquity of the limits (by its index), fitted as ``v50``
    fits them; shots at an obliquity without limits, or of another sphere, are refused."""
    from ..figures.velocity_response import ShotGroup  # noqa: PLC0415 (matplotlib)

    shots = Shots.from_csv(args.shots)
    radius, mass = shots.spheres(sphere)
    for declared, given, name in ((RADIUS, radius, "radius_mm"), (MASS, mass, "mass_g")):
        nominal = getattr(sphere, declared.name)
        if name not in spec.inputs and np.any(given != nominal):
            raise UsageError(
                f"--shots: {shown(args.shots, None)} gives shots a {name} other than the "
                f"spec's {nominal / declared.scale:g}: compare shots of the spec's sphere"
            )
    found = {}
    for obliquity, group in shots.groups_by_obliquity().items():
        degrees = user(IMPACT_OBLIQUITY, obliquity)
        at = np.flatnonzero(np.isclose(angles, degrees, rtol=1e-9, atol=1e-9))
        if at.size == 0:
            listed = ", ".join(f"{a:g}" for a in angles)
            raise UsageError(
                f"--shots: {shown(args.shots, None)} has shots at {degrees:g} deg, where no "
                f"limits are found (at {listed} deg): give --obliquities with theirs"
            )
        label = f"{args.shots} at {number(IMPACT_OBLIQUITY, obliquity)} deg"
        try:
            fit: V50Fit | str = fit_v50(
                group.impact_speed, group.perforated, group.weight, bootstrap=0, label=label
            )
        except V50Error as exc:
            fit = str(exc).removeprefix(f"{label}: ")
        found[int(at[0])] = ShotGroup(group.impact_speed, group.perforated, group.weight, fit)
    return found


def _speed(value: float | None, outside: str | None, speeds: tuple[float, float]) -> str:
    if value is not None:
        return f"{value:9.4g} m/s"
    return f"below {speeds[0]:g} m/s" if outside == "below" else f"beyond {speeds[1]:g} m/s"


def _text(where: str, name: str, report: dict[str, Any], speeds: tuple[float, float]) -> list[str]:
    """A limit's report as ``v50`` prints a fit: V50, sigma, V10, V90 and intervals."""
    counts = ", ".join(f"{report[key]:,} {MEANING[key]}" for key in OUTSIDE[name] if report[key])
    lines = [
        f"{where}: {NAMES[name]} of {report['samples']:,} samples, {report['within_range']:,} "
        f"within {speeds[0]:g}-{speeds[1]:g} m/s" + (f" ({counts})" if counts else "")
    ]
    for key in OUTSIDE[name]:
        if report[key] == report["samples"]:  # none in the range: said once, no quantile
            lines.append(f"  no {NAMES[name]} in the range: {ALL[key]}")
            return lines
    sigma = report["sigma_m_s"]
    for label, key in (("V50", "v50"), ("sigma", "sigma"), ("V10", "v10"), ("V90", "v90")):
        if key == "sigma":
            lines.append(f"  {'sigma':6s}" + ("   (limits outside the range)" if sigma is None
                                               else f"{sigma:9.4g} m/s"))  # fmt: skip
            continue
        value = _speed(report[f"{key}_m_s"], report[f"{key}_outside_range"], speeds)
        lines.append(f"  {label:6s}{value}  {interval(report[f'{key}_ci_m_s'])}")
    if report["gaps"]:
        side = "perforate below" if name == "ballistic" else "ricochet above"
        lines.append(f"  {report['gaps']:,} samples also {side} a band of another outcome")
    return lines


def _shots_text(args: argparse.Namespace, group: Any) -> str:
    where = f"  shots ({shown(args.shots, None)}, {group.weight.sum():g} at this obliquity)"
    fit = group.fit
    if not isinstance(fit, V50Fit):
        return f"{where}: no V50: {shown(fit, None)}"
    return (
        f"{where}: {fit.method} fit V50 {fit.v50_m_s:.4g} m/s {interval(fit.v50_ci_m_s)}, "
        f"sigma {fit.sigma_m_s:.4g} m/s, V10 {fit.v10_m_s:.4g}, V90 {fit.v90_m_s:.4g} m/s"
    )


def limits(
    spec: UncertaintySpec, simulation: Simulation, args: argparse.Namespace, out: Writer
) -> int:
    registry = simulation.registry
    angles = obliquities(spec, args)
    sphere = registry.sphere
    for name, declared in (("radius_mm", RADIUS), ("mass_g", MASS)):
        if name in spec.at:  # the spec's own sphere, when it gives one
            sphere = attrs.evolve(sphere, **{declared.name: spec.at[name] * declared.scale})
    shots = {} if args.shots is None else _shots(args, spec, angles, sphere)
    with reporting_scenes("uncertainty --limits"):
        found, kept = kept_limits(
            spec, registry, angles, archive_of(args), resume=args.resume, simulation=simulation
        )
    if args.png is not None:
        from ..figures.velocity_response import plot_velocity_response  # noqa: PLC0415

        figure = plot_velocity_response(
            found, shots, title=f"{plate_title(spec)}: probabilistic velocity response",
            provenance=figure_provenance(spec, simulation),
        )  # fmt: skip
        save_figure_atomically(figure, args.png, dpi=args.dpi)
    rows = []
    for k, one in enumerate(found):
        row = one.to_json()
        if k in shots:
            fit = shots[k].fit
            fitted = fit.to_json() if isinstance(fit, V50Fit) else {"error": fit}
            row["shots"] = {"shots_file": args.shots, **fitted}
        rows.append(row)
    first = found[0]
    if args.json:
        summary = {
            "samples": spec.samples, "method": spec.method, "seed": spec.seed,
            "confidence": 0.95, "search": first.search(), "limits": rows,
            "spec": spec.describe(), **provenance(simulation),
            "archive_record": kept.record,
        }  # fmt: skip
        out.say(json.dumps(summary, indent=2))
        return 0
    out.say(
        f"{spec.source}: limits of {spec.samples:,} samples ({spec.method}, seed {spec.seed}) "
        f"over {first.speeds[0]:g}-{first.speeds[1]:g} m/s, to {first.tolerance:g} m/s; 95% "
        "intervals: distribution-free (order statistics); V_p: a fraction p of the limits "
        "lie below it"
    )
    for k, row in enumerate(rows):
        where = f"{shown(spec.source, None)} at {row['obliquity_deg']:g} deg"
        for limit in ("ballistic", "ricochet"):
            for line in _text(where, limit, row[f"{limit}_limit"], first.speeds):
                out.say(line)
            if limit == "ballistic" and k in shots:  # the shots beside the model's V50
                out.say(_shots_text(args, shots[k]))
    stored(kept, out)
    if args.png is not None:
        out.say(f"figure: {args.png}")
    return 0
