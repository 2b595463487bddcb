"""How scenes and results show in a notebook: a short text (``__repr__``) and a small HTML
table (``_repr_html_``) of a :class:`~plateimpact.model.results.Result`, a trajectory, a
crater section, a batch of scenes and a batch's results. Every quantity is in the user's
unit (m/s, deg, mm, g, us), with the unit in the text or in the table's heading; no
array is printed whole (a table shows its first and last rows).

The objects are read through their columns (mappings of name to values), so that this
module, below the classes that use it, imports none of them.
"""

from __future__ import annotations

from collections.abc import Mapping, Sequence
from typing import Any

import numpy as np

from ..base.display import (
    DURATION,
    cell,
    counted,
    heading,
    html_block,
    html_fields,
    html_table,
    preview,
    quantity,
    short_repr,
    spread,
    unit,
)
from ..base.parameters import Parameter
from .fields import CORE_COLUMNS, CRATER_FIELDS, RESULT_FIELDS, TRAJECTORY_FIELDS, Outcome
from .tables import PLATE, SceneInputs

FIELD = RESULT_FIELDS
#: The result columns a row of a table shows: (heading, declaration in the unit shown).
ROW_RESULTS: tuple[tuple[str, Parameter], ...] = (
    ("exit speed", FIELD["exit_speed"]),
    ("exit obliquity", FIELD["exit_obliquity"]),
    ("max penetration", FIELD["max_penetration"]),
)
#: The scene columns a row of a table shows, impact first.
ROW_INPUTS = ("impact_speed", "impact_obliquity")


def scenes(size: int) -> str:
    """``1 scene``, ``1,000 scenes``."""
    return f"{size:,} scene" + ("" if size == 1 else "s")


def label(name: str) -> str:
    """A column's name as a heading says it: ``impact speed``."""
    return name.replace("_", " ")


def _failed(values: Mapping[str, Any]) -> str:
    """Where the plate failed, as ``plateimpact run`` says it."""
    if not values["plate_failed"]:
        return "no"
    return (
        f"at P = {quantity(FIELD['failure_penetration'], values['failure_penetration'])}, "
        f"Y = {quantity(FIELD['failure_lateral'], values['failure_lateral'])}, "
        f"t = {quantity(DURATION, values['failure_time'])}"
    )


def result_quantities(values: Mapping[str, Any]) -> list[tuple[str, str]]:
    """(what, value with its unit) of one result's columns ``values`` [SI]: what
    ``plateimpact run`` prints, line by line, and a Result's repr."""
    return [
        ("exit speed", quantity(FIELD["exit_speed"], values["exit_speed"])),
        ("exit obliquity", quantity(FIELD["exit_obliquity"], values["exit_obliquity"])),
        ("contact time", quantity(DURATION, values["contact_time"])),
        ("max penetration", quantity(FIELD["max_penetration"], values["max_penetration"])),
        ("plate failed", _failed(values)),
    ]


def result_repr(values: Mapping[str, Any]) -> str:
    outcome = Outcome(int(values["outcome"])).label
    return short_repr("Result", [outcome, *(f"{k} {v}" for k, v in result_quantities(values))])


def result_html(values: Mapping[str, Any]) -> str:
    failed = bool(values["plate_failed"])
    fields: list[tuple[str, object]] = [("outcome", Outcome(int(values["outcome"])).label)]
    fields += [(heading(what, d), cell(d, values[d.name])) for what, d in ROW_RESULTS]
    fields.insert(3, (heading("contact time", DURATION), cell(DURATION, values["contact_time"])))
    fields.append(("plate failed", "yes" if failed else "no"))
    if failed:
        fields += [
            (heading("failure penetration", FIELD["failure_penetration"]),
             cell(FIELD["failure_penetration"], values["failure_penetration"])),
            (heading("failure lateral", FIELD["failure_lateral"]),
             cell(FIELD["failure_lateral"], values["failure_lateral"])),
            (heading("failure time", DURATION), cell(DURATION, values["failure_time"])),
        ]  # fmt: skip
    return html_block("Result", html_fields(fields))


#: A path's facts: (what, its declaration or None for a label, the values shown: the
#: first and last, or the one).
PathPart = tuple[str, Parameter | None, tuple[float, ...] | str]


def trajectory_parts(
    columns: Mapping[str, np.ndarray], outcome: Outcome | None, state: Sequence[str]
) -> list[PathPart]:
    """What a recorded path says: samples, time span, outcome, and where its speed,
    obliquity and penetration went; never the arrays."""
    path, samples = TRAJECTORY_FIELDS, int(np.size(columns["time"]))
    parts: list[PathPart] = [
        ("samples", None, f"{samples:,}"),
        ("time", DURATION, ()),
        ("outcome", None, "not given" if outcome is None else outcome.label),
        ("speed", path["speed"], ()),
        ("obliquity", path["obliquity"], ()),
    ]
    if samples:
        ends = {name: (float(columns[name][0]), float(columns[name][-1]))
                for name in ("time", "speed", "obliquity")}  # fmt: skip
        parts = [(what, d, ends.get(what, shown)) for what, d, shown in parts]
        deepest = float(np.max(columns["penetration"]))
        parts.append(("max penetration", path["penetration"], (deepest,)))
    if state:
        parts.append(("failure state", None, ", ".join(state)))
    return parts


def _shown(declared: Parameter | None, values: tuple[float, ...] | str, units: bool) -> str:
    """A path's value: a label as it is, else its ends (``200 to 22.2 m/s``, or the unit
    left to a heading), ``none`` for a path of no samples."""
    if isinstance(values, str) or declared is None:
        return str(values)
    if not values:
        return "none"
    text = " to ".join(cell(declared, v) for v in values)
    return f"{text} {unit(declared)}".rstrip() if units else text


def trajectory_repr(parts: list[PathPart]) -> str:
    texts = {what: _shown(d, shown, units=True) for what, d, shown in parts}
    first = [f"{texts.pop('samples')} samples over {texts.pop('time')}", texts.pop("outcome")]
    return short_repr("Trajectory", [*first, *(f"{k} {v}" for k, v in texts.items())])


def trajectory_html(parts: list[PathPart]) -> str:
    fields: list[tuple[str, object]] = [
        (what if d is None else heading(what, d), _shown(d, shown, units=False))
        for what, d, shown in parts
    ]
    return html_block("Trajectory", html_fields(fields))


def crater_repr(lateral: np.ndarray, depth: np.ndarray) -> str:
    length = float(lateral[-1] - lateral[0]) if lateral.size else 0.0
    deepest = float(depth.max()) if depth.size else 0.0
    floor = CRATER_FIELDS["depth"]
    return short_repr(
        "CraterSection",
        [
            f"{lateral.size:,} points",
            f"length {quantity(CRATER_FIELDS['lateral'], length)}",
            f"depth up to {quantity(floor, deepest)}",
        ],
    )


def _input_label(inputs: SceneInputs, name: str) -> str:
    """A scene column's heading: its unit, or ``[SI]`` for a constant no plug-in given
    declares (its value is shown as stored)."""
    if name in CORE_COLUMNS or name in inputs.constants:
        return heading(label(name), inputs.declared(name))
    return f"{label(name)} [SI]"


def _ordered(columns: Mapping[str, np.ndarray]) -> list[str]:
    """Scene columns in the order tables show them: the impact, the rest of the core
    columns, then the plate constants."""
    core = [*ROW_INPUTS, *(n for n in CORE_COLUMNS if n not in ROW_INPUTS)]
    return [n for n in core if n in columns] + [n for n in columns if n not in CORE_COLUMNS]


def inputs_table(inputs: SceneInputs) -> str:
    """Each scene column's one value, few values or range; the plates by label."""
    fields: list[tuple[str, object]] = []
    if inputs.plate_labels is not None:
        fields.append(("plate", ", ".join(dict.fromkeys(inputs.plate_labels))))
    for name in _ordered(inputs.columns):
        shown = spread(inputs.declared(name), inputs.columns[name], with_unit=False)
        fields.append((_input_label(inputs, name), shown))
    return html_fields(fields, caption="inputs")


def inputs_parts(inputs: SceneInputs) -> list[str]:
    """The impact's columns in a short text: ``impact speed 50 to 1500 m/s (59 values)``."""
    parts = [f"{label(n)} {spread(inputs.declared(n), inputs.columns[n])}" for n in ROW_INPUTS]
    if inputs.plate_labels is not None:
        parts.insert(0, f"plates {', '.join(dict.fromkeys(inputs.plate_labels))}")
    return parts


#: What :func:`outcome_counts` counts, in order.
COUNTED = (*(outcome.label for outcome in Outcome), "plate failed")


def outcome_counts(columns: Mapping[str, np.ndarray]) -> list[tuple[str, int]]:
    """How many scenes ended in each outcome, and how many failed the plate."""
    codes = np.bincount(np.asarray(columns["outcome"], dtype=np.int64), minlength=4)
    found = [int(codes[int(outcome)]) for outcome in Outcome]
    found.append(int(np.count_nonzero(columns["plate_failed"])))
    return list(zip(COUNTED, found, strict=True))


def rows_table(
    size: int, inputs: SceneInputs | None, results: Mapping[str, np.ndarray] | None
) -> str:
    """The first and last scenes: their impact (and plate) and, with ``results``, the
    outcome and key figures, units in the headings."""
    shown, omitted = preview(size)
    header: list[str] = ["scene"]
    columns: list[list[object]] = [[str(i) for i in shown]]
    if inputs is not None:
        if inputs.plate_labels is not None:
            header.append(PLATE.name)
            columns.append([inputs.plate_labels[i] for i in shown])
        for name in ROW_INPUTS:
            declared = inputs.declared(name)
            header.append(heading(label(name), declared))
            columns.append([cell(declared, inputs.columns[name][i]) for i in shown])
    if results is not None:
        header.append("outcome")
        columns.append([Outcome(int(results["outcome"][i])).label for i in shown])
        for what, declared in ROW_RESULTS:
            header.append(heading(what, declared))
            columns.append([cell(declared, results[declared.name][i]) for i in shown])
        header.append("plate failed")
        columns.append(["yes" if results["plate_failed"][i] else "no" for i in shown])
    rows = [list(row) for row in zip(*columns, strict=True)]
    return html_table(header, rows, caption="scenes", omitted=omitted)


def batch_result_repr(
    size: int, columns: Mapping[str, np.ndarray], inputs: SceneInputs | None, kept: list[str]
) -> str:
    parts = [f"{scenes(size)}: {counted(outcome_counts(columns))}"]
    parts += inputs_parts(inputs) if inputs is not None else ["inputs not attached"]
    if kept:
        parts.append(f"with {' and '.join(kept)}")
    return short_repr("BatchResult", parts)


def batch_result_html(
    size: int, columns: Mapping[str, np.ndarray], inputs: SceneInputs | None, kept: list[str]
) -> str:
    counts = outcome_counts(columns)
    tables = [] if inputs is None else [inputs_table(inputs)]
    tables.append(html_table([what for what, _ in counts], [[f"{n:,}" for _, n in counts]],
                             caption="outcomes"))  # fmt: skip
    tables.append(rows_table(size, inputs, columns))
    with_kept = f", with {' and '.join(kept)}" if kept else ""
    return html_block(f"BatchResult: {scenes(size)}{with_kept}", *tables)


def scenes_repr(size: int, inputs: SceneInputs) -> str:
    constants = [n for n in inputs.columns if n not in CORE_COLUMNS]
    sphere = [f"{label(n)} {spread(inputs.declared(n), inputs.columns[n])}"
              for n in ("radius", "mass", "thickness") if n in inputs.columns]  # fmt: skip
    listed = f"plate constants {', '.join(constants)}" if constants else ""
    return short_repr("SceneBatch", [scenes(size), *inputs_parts(inputs), *sphere, listed])


def scenes_html(size: int, inputs: SceneInputs) -> str:
    tables = [inputs_table(inputs), rows_table(size, inputs, None)]
    return html_block(f"SceneBatch: {scenes(size)}", *tables)


def runs_repr(
    kind: str, name: str, size: int, inputs: SceneInputs, runs: Mapping[str, Mapping[str, Any]]
) -> str:
    """A study's runs: how many over how many scenes, the impacts, each run's outcomes."""
    parts = [f"{name!r}: {len(runs)} runs over {scenes(size)}", *inputs_parts(inputs)]
    parts += [f"{run}: {counted(outcome_counts(columns))}" for run, columns in runs.items()]
    return short_repr(kind, parts)


def runs_html(
    kind: str,
    name: str,
    description: str,
    size: int,
    inputs: SceneInputs,
    runs: Mapping[str, Mapping[str, Any]],
) -> str:
    counts = {run: outcome_counts(columns) for run, columns in runs.items()}
    header = ["run", *COUNTED]
    rows = [[run, *(f"{n:,}" for _, n in found)] for run, found in counts.items()]
    tables = [html_fields([("description", description)])] if description else []
    tables += [inputs_table(inputs), html_table(header, rows, caption="outcomes of each run")]
    return html_block(f"{kind} {name}: {len(runs)} runs over {scenes(size)}", *tables)
