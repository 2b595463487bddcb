"""Numbers and tables for people: a value [SI] in the unit its declaration gives, to the
digits asked for, with the unit; and the short text and the small HTML table a notebook
shows of an object (``__repr__``, ``_repr_html_``).

Both come from the declarations (:class:`~plateimpact.base.parameters.Parameter`: scene
columns, result columns, plate constants) that name the ``--json`` keys and CSV headers,
so that a unit is written in one place (``plateimpact.base.units``): the command
line's text is formatted here too. Every piece of text a table or a repr shows goes
through ``html.escape`` or :func:`~plateimpact.printable`, so that a
label from someone else's file (a preset name, a plate's material, a plug-in's setting)
shows as text, never as markup or a terminal's control sequence. No style sheet and no
script: a table takes the notebook's own look.
"""

from __future__ import annotations

import html
import math
from collections.abc import Iterable, Sequence

import numpy as np

from .parameters import Parameter
from .units import deg, mm, us
from .untrusted import printable

#: Quantities shown that no column declares: an angle of the model (alpha*), a length
#: (P*), a contact time in microseconds, a speed.
ANGLE = Parameter("angle", "an angle", "rad", display_unit="deg", scale=deg)
LENGTH = Parameter("length", "a length", "m", display_unit="mm", scale=mm)
DURATION = Parameter("duration", "a duration", "s", display_unit="us", scale=us)
SPEED = Parameter("speed", "a speed", "m/s")
#: Distinct values of a column listed one by one; more are shown as a range.
LISTED_VALUES = 6
#: Rows of a table shown at the most: the first and the last half of them.
SHOWN_ROWS = 10


def user(declared: Parameter, value: float) -> float:
    """``value`` [SI] in the user's unit: the shortest number that reads back exactly
    (``60``, not ``59.99999999999999``) where there is one, else the quotient."""
    exact = declared.user_number(float(value))
    return float(value) / declared.scale if exact is None else exact


def number(declared: Parameter, value: float, digits: int = 6, style: str = "g") -> str:
    """``value`` [SI] in the user's unit, without it: ``digits`` significant digits
    (``style`` ``g``) or decimals (``f``)."""
    return f"{float(value) / declared.scale:.{digits}{style}}"


def unit(declared: Parameter) -> str:
    """The unit the user reads ``declared`` in (empty for a pure number)."""
    return "" if declared.user_unit == "1" else declared.user_unit


def quantity(declared: Parameter, value: float, digits: int = 6, style: str = "g") -> str:
    """``value`` [SI] in the user's unit, with it: ``640 m/s``, ``60 deg``, ``1.25 mm``."""
    text = number(declared, value, digits, style)
    return f"{text} {unit(declared)}".rstrip()


def heading(label: str, declared: Parameter) -> str:
    """A column's heading with the unit it is shown in: ``exit speed [m/s]``."""
    shown = unit(declared)
    return f"{label} [{shown}]" if shown else label


def cell(declared: Parameter, value: float | None, digits: int = 6, style: str = "g") -> str:
    """A table cell: ``value`` [SI] in the user's unit, without it (the heading has it),
    to ``digits`` significant digits (``style`` ``g``) or decimals (``f``); ``-`` for
    none (None or NaN)."""
    if value is None or math.isnan(float(value)):
        return "-"
    return f"{user(declared, value):.{digits}{style}}"


def spread(
    declared: Parameter,
    values: np.ndarray | Sequence[float],
    with_unit: bool = True,
    digits: int = 6,
    style: str = "g",
) -> str:
    """What a column holds, in the user's unit (each value as :func:`cell` writes it):
    its one value, its few values, or its range and how many distinct values (``50 to
    1500 m/s (59 values)``; without the unit for a table whose heading has it)."""
    distinct = np.unique(np.asarray(values, dtype=float))
    if distinct.size == 0:
        return "none"
    if distinct.size > LISTED_VALUES:  # the ends only: a million values need no text each
        low, high = (cell(declared, float(x), digits, style) for x in distinct[[0, -1]])
        text, suffix = f"{low} to {high}", f" ({distinct.size:,} values)"
    else:
        text = ", ".join(cell(declared, float(x), digits, style) for x in distinct)
        suffix = ""
    shown_unit = unit(declared) if with_unit else ""
    return f"{text} {shown_unit}".rstrip() + suffix


def counted(counts: Iterable[tuple[str, int]]) -> str:
    """``3 ricochet, 0 embedment, 5 perforation``."""
    return ", ".join(f"{n:,} {what}" for what, n in counts)


def short_repr(kind: str, parts: Iterable[str]) -> str:
    """``Kind(part; part; ...)`` as one inert line: a text repr that says what the object
    holds, in user units, without dumping its arrays."""
    return printable(f"{kind}({'; '.join(p for p in parts if p)})")


def _escaped(value: object) -> str:
    return html.escape(printable(value), quote=True)


def preview(size: int) -> tuple[list[int], int]:
    """The rows of ``size`` a table shows (the first and the last few, at most
    :data:`SHOWN_ROWS`) and how many it leaves out between them."""
    if size <= SHOWN_ROWS:
        return list(range(size)), 0
    half = SHOWN_ROWS // 2
    return [*range(half), *range(size - half, size)], size - 2 * half


def html_table(
    header: Sequence[str],
    rows: Sequence[Sequence[object]],
    caption: str | None = None,
    omitted: int = 0,
) -> str:
    """A table with a heading row (units in the headings: :func:`heading`); ``omitted``
    rows left out between the first and the second half of ``rows`` (:func:`preview`)
    are said in a row of their own. Every cell escaped."""
    lines = ["<table>"]
    if caption is not None:
        lines.append(f"<caption>{_escaped(caption)}</caption>")
    lines.append("<tr>" + "".join(f"<th>{_escaped(h)}</th>" for h in header) + "</tr>")
    cells = ["<tr>" + "".join(f"<td>{_escaped(c)}</td>" for c in row) + "</tr>" for row in rows]
    if omitted:
        gap = f'<tr><td colspan="{len(header)}">... {omitted:,} more rows ...</td></tr>'
        cells.insert(len(cells) // 2, gap)
    lines += cells
    lines.append("</table>")
    return "\n".join(lines)


def html_fields(fields: Sequence[tuple[str, object]], caption: str | None = None) -> str:
    """A table of named values, one row each (``exit speed [m/s]`` | ``22.2``); every cell
    escaped."""
    lines = ["<table>"]
    if caption is not None:
        lines.append(f"<caption>{_escaped(caption)}</caption>")
    for name, value in fields:
        lines.append(f"<tr><th>{_escaped(name)}</th><td>{_escaped(value)}</td></tr>")
    lines.append("</table>")
    return "\n".join(lines)


def html_block(title: str, *tables: str) -> str:
    """An object's HTML: its name in bold (escaped), then its tables (already escaped)."""
    return "\n".join(["<div>", f"<strong>{_escaped(title)}</strong>", *tables, "</div>"])
