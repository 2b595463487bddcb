"""Stored limits and maps in ``show`` and ``compare`` (docs/archive.md)."""

from __future__ import annotations

import json
import math

from ..base.errors import UnknownNameError
from ..base.untrusted import printable
from ..limits import LimitsComparison, OutcomeMap, compare_limits, read_limits
from ..limits.archived import KIND_MAP, NAMES, attributes_of
from ..limits.lines import OBLIQUITY, SPEED, LimitLine
from ..provenance.code import summary as code_summary
from ..storage import stored_attributes as typed
from ..storage.archive import Archive
from ..storage.records import LIMITS
from .common import UsageError
from .describe import seconds, shown
from .formatting import AXES, unit
from .writer import Writer

#: Each axis's unit as printed, from its declaration.
_UNIT = {axis: unit(declared) for axis, declared in AXES.items()}


def user(axis: str, value: float) -> float:
    """``value`` [SI] on ``axis`` in the unit its declaration prints it in."""
    return value / AXES[axis].scale


def _digits(axis: str, tolerance: float) -> int:
    """Decimals that show a boundary to its accuracy (half the tolerance)."""
    return max(0, math.ceil(-math.log10(user(axis, tolerance) / 2)))


def _value(axis: str, value: float | None, digits: int) -> str:
    return "none" if value is None else f"{user(axis, value):.{digits}f} {_UNIT[axis]}"


def _fixed(axis: str, fixed: float) -> str:
    """A line's fixed coordinate, as ``obliquity 45 deg`` or ``speed 600 m/s``."""
    if axis == SPEED:
        return f"obliquity {user(OBLIQUITY, fixed):g} {_UNIT[OBLIQUITY]}"
    return f"speed {fixed:g} m/s"


def _named(axis: str, line: LimitLine, digits: int) -> str:
    if axis == OBLIQUITY:
        critical = line.critical_ricochet_obliquity
        return f"critical ricochet obliquity {_value(axis, critical, digits)}"
    parts = [f"ballistic limit {_value(axis, line.ballistic_limit, digits)}"]
    lowest = line.lowest_perforation
    if lowest is not None and lowest != line.ballistic_limit:
        parts.append(f"lowest perforation {_value(axis, lowest, digits)}")
    parts.append(f"ricochet limit {_value(axis, line.ricochet_limit, digits)}")
    return ", ".join(parts)


def _model(model: object) -> str:
    """The stored model (an archive's JSON) as one inert line."""
    if not isinstance(model, dict):
        return shown(model)

    def slot(kind: str) -> str:
        settings = model.get(f"{kind}_settings") or {}
        return f"{model.get(kind)}" + (f" {settings}" if settings else "")

    return shown(
        f"{slot('resistance')} + {slot('failure')}, rest_speed_fraction "
        f"{model.get('rest_speed_fraction')}, integrator {model.get('integrator')} "
        f"{model.get('integrator_settings')}"
    )


def _plate(plate: object) -> str:
    """``2024-T3 3.18 mm (a_N_m2 1.01e+09, ...)`` from a stored plate object."""
    if not isinstance(plate, dict):
        return shown(plate)
    constants = ", ".join(
        f"{shown(k)} {v:g}"
        for k, v in plate.items()
        if isinstance(v, float) and k != "thickness_mm"
    )
    thickness = plate.get("thickness_mm")
    number = isinstance(thickness, int | float) and not isinstance(thickness, bool)
    return (
        f"{shown(plate.get('material'))} {f'{thickness:g}' if number else shown(thickness)} mm "
        f"({constants})"
    )


#: The kinds of record an uncertainty study keeps (uncertainty.archived) start so.
UNCERTAINTY = "uncertainty_"


def uncertainty_lines(archive: Archive, name: str) -> list[str]:
    """What an uncertainty study's record holds (sampled limits, Sobol' indices, a
    probability map): the plate, the model, the spec's inputs and sampling, what made
    it; its numbers are read with plateimpact.uncertainty.archived.read_stored."""
    attributes = archive.record(name).attributes
    what = f"archive {archive.path}: {LIMITS}/{printable(name)}"
    kind = typed.text(attributes, "kind", what)
    spec = typed.json_value(attributes, "spec", what, dict)
    model = typed.json_value(attributes, "model", what, dict)
    settings = typed.json_value(attributes, "settings", what, dict)
    inputs = spec.get("inputs")
    listed = ", ".join(shown(k) for k in inputs) if isinstance(inputs, dict) else shown(inputs)
    versions = typed.json_value(attributes, "versions", what, dict)
    return [
        f"{LIMITS}/{shown(name, None)}: {shown(kind.removeprefix(UNCERTAINTY))} of an "
        "uncertainty study",
        f"  plate {_plate(typed.json_value(attributes, 'plate', what, dict))}",
        f"  model: {_model(model)}",
        f"  samples {shown(spec.get('samples'))} ({shown(spec.get('method'))}, seed "
        f"{shown(spec.get('seed'))}) of {listed}; settings {shown(json.dumps(settings), 300)}",
        f"  made {shown(attributes.get('creation_time'))} on {shown(attributes.get('host'))}, "
        f"plateimpact {shown(versions.get('plateimpact'))}, commit "
        f"{shown(str(attributes.get('git_commit'))[:12])}",
        *(
            f"  {line}"
            for line in code_summary(typed.json_value(attributes, "plugins", what, dict))
        ),
    ]


def show_stored(archive: Archive, out: Writer) -> None:
    """Print every stored limits and map: what, plate, model, tolerance and resolution,
    then one line per line with its named limits. Every piece of the archive's text is
    printed inert (describe.shown)."""
    for name in archive.limits_names():
        kind = archive.record(name).attributes.get("kind")
        if isinstance(kind, str) and kind.startswith(UNCERTAINTY):
            out.say("\n".join(uncertainty_lines(archive, name)))
            continue
        found = read_limits(archive, name)
        meta = attributes_of(archive, name)
        limits = found.limits if isinstance(found, OutcomeMap) else found
        axis, unit = limits.axis, _UNIT[limits.axis]
        if meta.get("kind") == KIND_MAP and isinstance(found, OutcomeMap):
            rows, columns = found.shape
            degrees = [user(OBLIQUITY, x) for x in (found.obliquities[0], found.obliquities[-1])]
            what = (
                f"outcome map, {rows} obliquities x {columns} speeds "
                f"({degrees[0]:g}-{degrees[1]:g} deg, {found.speeds[0]:g}-{found.speeds[-1]:g} m/s)"
            )
        else:
            what = f"limits along {NAMES[axis]}, {len(limits.lines)} line(s)"
        digits = _digits(axis, limits.tolerance)
        versions = meta.get("versions")
        version = versions.get("plateimpact") if isinstance(versions, dict) else versions
        lines = [
            f"{LIMITS}/{shown(name, None)}: {what}",
            f"  plate {_plate(meta.get('plate'))}",
            f"  model: {_model(limits.model)}",
            f"  tolerance {user(axis, limits.tolerance):g} {unit}, resolution "
            f"{user(axis, limits.resolution):g} {unit}; {limits.scenes} scenes, "
            f"{limits.passes} passes, wall {seconds(limits.seconds)}",
            *(
                f"  {_fixed(axis, line.fixed)}: {_named(axis, line, digits)}"
                for line in limits.lines
            ),
            f"  made {shown(meta.get('creation_time'))} on {shown(meta.get('host'))}, plateimpact "
            f"{shown(version)}, commit {shown(str(meta.get('git_commit'))[:12])}",
            *(f"  {line}" for line in code_summary(meta.get("plugins"))),
        ]
        out.say("\n".join(lines))


def _is_stored(name: str, stored: list[str]) -> bool:
    return name in stored or (name.startswith(f"{LIMITS}/") and name[len(LIMITS) + 1 :] in stored)


def kinds(archive: Archive, names: list[str]) -> list[str]:
    """For each name, ``limits`` or ``run``; a name that is neither, or both, is a
    one-line error listing what the archive holds."""
    stored = archive.limits_names()
    found = []
    for name in names:
        if name.startswith(f"{LIMITS}/") and _is_stored(name, stored):
            found.append("limits")
            continue
        try:
            archive.resolve(name)
            run = True
        except UnknownNameError as exc:
            if not _is_stored(name, stored):
                if not stored or "ambiguous" in str(exc):
                    raise
                runs = ", ".join(archive.runs()) or "none"
                kept = ", ".join(f"{LIMITS}/{s}" for s in stored)
                raise UnknownNameError(
                    f"no run {name!r} nor stored limits of that name in {archive.path} "
                    f"(runs: {runs}; limits: {kept})"
                ) from None
            run = False
        if run and _is_stored(name, stored):
            raise UsageError(
                f"{name!r} names both a run and stored limits in {archive.path}; write "
                f"STUDY/RUN or {LIMITS}/{name}"
            )
        found.append("run" if run else "limits")
    return found


def _text(name_a: str, name_b: str, comparison: LimitsComparison) -> str:
    axis = comparison.axis
    unit = _UNIT[axis]
    digits = _digits(axis, max(comparison.tolerance_a, comparison.tolerance_b))

    def at(value: float | None) -> str:
        return "-" if value is None else f"{user(axis, value):.{digits}f}"

    name_a, name_b = shown(name_a, None), shown(name_b, None)
    out = [
        f"{name_b} against {name_a}: {len(comparison.lines)} line(s) along {NAMES[axis]} "
        f"in both (shift: {name_b} - {name_a})"
    ]
    for line in comparison.lines:
        where = _fixed(axis, line.fixed)
        for s in line.boundaries:
            a_at = None if s.a is None else s.a.at
            b_at = None if s.b is None else s.b.at
            shift = s.shift
            moved = "only in " + (name_a if s.b is None else name_b) if shift is None else (
                f"shift {user(axis, shift):+.{digits}f} {unit}"
            )  # fmt: skip
            out.append(
                f"  {where}: {s.below.label} -> {s.above.label}: {name_a} {at(a_at)}, "
                f"{name_b} {at(b_at)} {unit}; {moved}"
            )
        for owner, bands in ((name_a, line.bands_only_in_a), (name_b, line.bands_only_in_b)):
            for band in bands:
                out.append(
                    f"  {where}: band {band.regime.label} {at(band.start)}-{at(band.end)} "
                    f"{unit} only in {owner}"
                )
    for owner, values in (
        (name_a, comparison.lines_only_in_a),
        (name_b, comparison.lines_only_in_b),
    ):
        for value in values:
            out.append(f"  {_fixed(axis, value)}: the line is only in {owner}")
    return "\n".join(out)


def compare_stored(archive: Archive, name_a: str, name_b: str, as_json: bool, out: Writer) -> None:
    """Print how each boundary moved from stored limits ``name_a`` to ``name_b``."""
    a, b = read_limits(archive, name_a), read_limits(archive, name_b)
    axis_a, axis_b = (x.limits.axis if isinstance(x, OutcomeMap) else x.axis for x in (a, b))
    if axis_a != axis_b:
        raise UsageError(
            f"{name_a} runs along {NAMES[axis_a]} and {name_b} along {NAMES[axis_b]}: "
            "compare limits along the same axis"
        )
    comparison = compare_limits(a, b)
    if as_json:
        out.say(json.dumps({"a": name_a, "b": name_b, **comparison.to_json()}, indent=2))
        return
    out.say(_text(name_a, name_b, comparison))
