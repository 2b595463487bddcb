"""Numbers for people: a value [SI] in the unit its declaration gives, to the digits asked
for, with the unit. The human output of every command is formatted here, from the same
declarations (:class:`~plateimpact.base.parameters.Parameter`: scene columns, result
columns, plate constants) that name the ``--json`` keys and CSV headers, so that a unit
is written in one place (:mod:`plateimpact.base.units`)."""

from __future__ import annotations

from ..base.parameters import Parameter
from ..base.units import deg, mm, us
from ..base.untrusted import printable
from ..model.scene import IMPACT_OBLIQUITY, IMPACT_SPEED

__all__ = ["ANGLE", "AXES", "DURATION", "IMPACT_OBLIQUITY", "IMPACT_SPEED", "LENGTH", "number",
           "quantity", "shown", "unit", "user"]  # fmt: skip

#: Longest piece of a file's text printed [characters] (a longer one is cut, "...").
LONGEST_TEXT = 200

#: Quantities the text shows that no column declares: an angle of the model (alpha*), a
#: length (P*), a contact time in microseconds.
ANGLE = Parameter("angle", "an angle", "rad", display_unit="deg", scale=deg)
LENGTH = Parameter("length", "a length", "m", display_unit="mm", scale=mm)
DURATION = Parameter("duration", "a duration", "s", display_unit="us", scale=us)
#: The declaration of each axis of a limit line (plateimpact.limits.lines: SPEED, OBLIQUITY).
AXES = {IMPACT_SPEED.name: IMPACT_SPEED, IMPACT_OBLIQUITY.name: IMPACT_OBLIQUITY}


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


def shown(value: object, limit: int | None = LONGEST_TEXT) -> str:
    """Text from a file (an archive's, a shot file's), as one inert line of at most
    ``limit`` characters."""
    return printable(value, limit)
