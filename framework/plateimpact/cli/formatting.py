"""Numbers for people on the command line: the formatting of
:mod:`plateimpact.base.display` (a value [SI] in the unit its declaration gives, to the
digits asked for, with the unit), and text from someone else's file as one inert line.
The human output of every command is formatted with these, from the same declarations
(:class:`~plateimpact.base.parameters.Parameter`: scene columns, result columns, plate
constants) that name the ``--json`` keys and CSV headers, so that a unit is written in
one place (:mod:`plateimpact.base.units`)."""

from __future__ import annotations

from collections.abc import Sequence

from ..base.display import ANGLE, DURATION, LENGTH, number, quantity, unit, user
from ..base.untrusted import printable
from ..model.scene import IMPACT_OBLIQUITY, IMPACT_SPEED

__all__ = ["ANGLE", "AXES", "DURATION", "IMPACT_OBLIQUITY", "IMPACT_SPEED", "LENGTH", "interval",
           "number", "quantity", "shown", "unit", "user"]  # fmt: skip

#: Longest piece of a file's text printed [characters] (a longer one is cut, "...").
LONGEST_TEXT = 200

#: The declaration of each axis of a limit line (plateimpact.limits.lines: SPEED, OBLIQUITY).
AXES = {IMPACT_SPEED.name: IMPACT_SPEED, IMPACT_OBLIQUITY.name: IMPACT_OBLIQUITY}


def shown(value: object, limit: int | None = LONGEST_TEXT) -> str:
    """Text from a file (an archive's, a shot file's), as one inert line of at most
    ``limit`` characters."""
    return printable(value, limit)


def interval(ends: Sequence[float | None] | None) -> str:
    """A confidence interval as ``v50`` prints it: ``[low, high]`` to 4 digits,
    ``unbounded`` for an end the data do not bound (None), ``-`` for none at all."""
    if ends is None:
        return "-"
    low, high = ("unbounded" if x is None else f"{x:.4g}" for x in ends)
    return f"[{low}, {high}]"
