"""Parameters: the one declaration of each quantity's unit, range, description, default
and command-line flag.

Every number a user can give plateimpact — a sphere's radius, a plate constant such as
P*, an integrator's tolerance — is declared once, as a :class:`Parameter`. Everything
else is derived from that declaration: the range check and its one-line message, attrs
fields (:meth:`Parameter.field`), command-line help and parsing, plate-file keys and the
units written to archives and JSON. Values are SI inside; ``display_unit`` and ``scale``
say how users write them (``mm``, ``deg``).
"""

from __future__ import annotations

import math
from collections.abc import Callable
from typing import Any

import attrs
import numpy as np

from .errors import ParameterError
from .untrusted import load_json

#: SI units that are written differently in file keys and JSON names (``a_N_m2``).
_KEY_UNITS = {"1": "", "N/m^2": "N_m2", "kg/m^3": "kg_m3", "m/s": "m_s"}


def _fmt(x: float) -> str:
    if math.isnan(x):
        return "nan"
    if math.isinf(x):
        return "inf" if x > 0 else "-inf"
    return f"{x:.6g}"


@attrs.frozen
class Range:
    """An allowed interval [SI units]; ``math.inf`` for no bound.

    ``allow_inf`` admits +inf itself (a plate that never fails has P* = inf). NaN is never
    allowed.
    """

    low: float = -math.inf
    high: float = math.inf
    low_open: bool = False
    high_open: bool = False
    allow_inf: bool = False

    def contains(self, value: Any) -> np.ndarray:
        """Element-wise membership."""
        x = np.asarray(value, dtype=float)
        ok = (x > self.low) if self.low_open else (x >= self.low)
        ok &= (x < self.high) if self.high_open else (x <= self.high)
        if not self.allow_inf:
            ok &= np.isfinite(x)
        return np.asarray(ok & ~np.isnan(x))

    def describe(self, scale: float = 1.0, unit: str = "") -> str:
        """The interval in display units: ``in [0, 90) deg``, ``> 0 mm``."""
        low, high = self.low / scale, self.high / scale
        unit = f" {unit}" if unit else ""
        if math.isinf(high) and math.isinf(low):
            text = "a number"
        elif math.isinf(high):
            text = f"{'>' if self.low_open else '>='} {_fmt(low)}{unit}"
        elif math.isinf(low):
            text = f"{'<' if self.high_open else '<='} {_fmt(high)}{unit}"
        else:
            left, right = "(" if self.low_open else "[", ")" if self.high_open else "]"
            text = f"in {left}{_fmt(low)}, {_fmt(high)}{right}{unit}"
        return text + (" (inf allowed)" if self.allow_inf else "")


NO_DEFAULT = object()


@attrs.frozen
class Parameter:
    """Everything plateimpact knows about one quantity.

    Parameters
    ----------
    name : str
        The Python name (``critical_penetration``): attrs field, batch column, archive
        dataset, ``--set`` name.
    description : str
        One line for help text and archive attributes.
    unit : str
        The SI unit of the value inside (``"m"``, ``"N/m^2"``, ``"1"``).
    range : Range
        Allowed values [SI]; checked for numbers only.
    display_unit, scale : str, float
        The unit users write it in and the SI value of one such unit (``"mm"``, 1e-3).
        Default: the SI unit itself.
    default : object
        The SI value when none is given; ``NO_DEFAULT`` for a required quantity.
    kind : type
        ``float``, ``int``, ``bool`` or ``str`` (a setting's type; quantities are float).
    optional : bool
        ``None`` is allowed (``fixed_step=None``: adaptive).
    choices : tuple of str
        The allowed strings of a ``str`` parameter.
    flag : str or None
        The command-line flag that sets it directly (``--pstar``), if any.
    short : str or None
        The stem of its file and JSON key (``pstar`` gives ``pstar_mm``); default ``name``.
    convert : callable or None
        Turns what users give (e.g. rows or a CSV path) into the value; replaces the
        number checks.
    to_json : callable or None
        The value as JSON for archives and outputs (default: the value itself).
    """

    name: str
    description: str
    unit: str = "1"
    range: Range = Range()
    display_unit: str | None = None
    scale: float = 1.0
    default: object = NO_DEFAULT
    kind: type = float
    optional: bool = False
    choices: tuple[str, ...] = ()
    flag: str | None = None
    short: str | None = None
    convert: Callable[[Any], Any] | None = attrs.field(default=None, eq=False)
    to_json: Callable[[Any], Any] | None = attrs.field(default=None, eq=False)

    # -- derived facts -------------------------------------------------------------

    @property
    def user_unit(self) -> str:
        """The unit users write the value in."""
        return self.display_unit or self.unit

    @property
    def key(self) -> str:
        """The name with its unit, for files and JSON (``pstar_mm``, ``a_N_m2``, ``c``)."""
        stem = self.short or self.name
        unit = _KEY_UNITS.get(self.user_unit, self.user_unit.replace("/", "_").replace("^", ""))
        return f"{stem}_{unit}" if unit and self.kind is float else stem

    @property
    def has_default(self) -> bool:
        return self.default is not NO_DEFAULT

    def describe_range(self) -> str:
        """The allowed values as users write them (``> 0 mm``, ``one of DOP853, RK45``)."""
        if self.choices:
            return f"one of {', '.join(self.choices)}"
        if self.kind is bool:
            return "true or false"
        if self.convert is not None:
            return "as described"
        text = self.range.describe(self.scale, "" if self.user_unit == "1" else self.user_unit)
        if self.kind is int:
            text = f"an integer {text}"
        return text + (" or none" if self.optional else "")

    def help(self) -> str:
        """One line of help: description, unit, range, default."""
        unit = "" if self.user_unit == "1" else f" [{self.user_unit}]"
        default = ""
        if self.has_default:
            default = f"; default {self.format(self.default)}"
        allowed = "" if self.convert is not None else f"; {self.describe_range()}"
        return f"{self.description}{unit}{allowed}{default}"

    def format(self, value: object) -> str:
        """``value`` [SI] as users write it."""
        if value is None:
            return "none"
        if isinstance(value, bool):
            return "true" if value else "false"
        if isinstance(value, int | float) and self.kind in (float, int):
            return _fmt(float(value) / self.scale) if self.kind is float else str(value)
        return str(self.json_value(value))

    def user_number(self, value: float) -> float | None:
        """``value`` [SI] in the user's unit, as the shortest number that :meth:`parse`
        turns back into exactly ``value`` (``45``, not ``45.00000000000001``); None if no
        number does (about 2% of values computed in SI, e.g. a mass from a density, fall
        between the numbers a unit of 1e-3 can reach)."""
        value = float(value)
        if self.scale == 1.0 or not math.isfinite(value):
            return value
        naive = value / self.scale
        candidates = {float(f"{naive:.{digits}g}") for digits in range(1, 18)}
        for direction in (math.inf, -math.inf):  # the neighbours of the naive quotient
            neighbour = naive
            for _ in range(3):
                neighbour = math.nextafter(neighbour, direction)
                candidates.add(neighbour)
        exact = [c for c in candidates if c * self.scale == value]
        if not exact:
            return None
        return min(exact, key=lambda c: (len(repr(c)), abs(c - naive)))

    def json_value(self, value: object) -> object:
        """``value`` as a JSON value [SI] (a table becomes its rows)."""
        if self.to_json is not None and value is not None:
            return self.to_json(value)
        if isinstance(value, np.generic):
            return value.item()
        return value

    # -- checks ----------------------------------------------------------------------

    def error(self, problem: str) -> ParameterError:
        return ParameterError(self.name, f"{self.name} must be {problem}")

    def check(self, value: Any) -> None:
        """Raise :class:`ParameterError` naming the parameter unless every value is in its
        range; an array names the first bad scene."""
        ok = self.range.contains(value)
        if np.all(ok):
            return
        values = np.asarray(value, dtype=float)
        first = float(values[~ok].ravel()[0]) if values.ndim else float(values)
        unit = "" if self.user_unit == "1" else self.user_unit
        where = f" (scene {int(np.flatnonzero(~ok)[0])})" if values.ndim else ""
        got = f"{_fmt(first / self.scale)} {unit}".rstrip()
        raise self.error(f"{self.range.describe(self.scale, unit)}, got {got}{where}")

    def validate(self, value: Any) -> Any:
        """A Python value (SI) checked against the declaration and converted to its kind."""
        if value is None and self.optional:
            return None
        if self.convert is not None:
            return self.convert(value)
        if self.kind is bool:
            if not isinstance(value, bool | np.bool_):
                raise self.error(f"true or false, got {value!r}")
            return bool(value)
        if self.kind is str:
            if not isinstance(value, str) or (self.choices and value not in self.choices):
                raise self.error(f"{self.describe_range()}, got {value!r}")
            return value
        number = isinstance(value, int | float | np.integer | np.floating)
        if isinstance(value, bool | np.bool_) or not number:
            kind = "an integer" if self.kind is int else "a number"
            raise self.error(f"{kind}, got {value!r}")
        try:
            as_float = float(value)  # an int beyond 1.8e308 has no float: out of any range
        except OverflowError:
            raise self.error(f"{self.describe_range()}, got an integer beyond 1.8e308") from None
        if self.kind is int:
            whole = isinstance(value, int | np.integer) or as_float.is_integer()
            if not whole:  # 1.5, inf and nan alike
                raise self.error(f"an integer, got {value!r}")
            self.check(as_float)
            return int(value)
        self.check(as_float)
        return as_float

    def parse(self, text: str) -> Any:
        """A value from command-line text in the user's unit (``3.0`` mm -> 3e-3 m)."""
        word = text.strip()
        if self.optional and word.lower() in ("none", "null", ""):
            return None
        if self.convert is not None or self.kind is str:
            return self.validate(word)
        if self.kind is bool:
            lowered = word.lower()
            if lowered not in ("true", "false", "1", "0", "yes", "no"):
                raise self.error(f"true or false, got {text!r}")
            return lowered in ("true", "1", "yes")
        try:
            number = float(word)
        except ValueError:
            raise self.error(f"{self.describe_range()}, got {text!r}") from None
        if self.kind is int:
            return self.validate(int(number) if number.is_integer() else number)
        return self.validate(number * self.scale)

    # -- attrs -----------------------------------------------------------------------

    def field(self, **kwargs: Any) -> Any:
        """An attrs field holding this parameter: converted and checked on construction,
        with the declaration in its metadata (``attrs.fields(cls).x.metadata``)."""
        if self.has_default and "default" not in kwargs and "factory" not in kwargs:
            kwargs["default"] = self.default
        metadata = {**kwargs.pop("metadata", {}), "parameter": self}
        return attrs.field(converter=self.validate, metadata=metadata, **kwargs)


def check_instance(name: str, value: object, kind: type) -> None:
    """Raise :class:`ParameterError` naming ``name`` unless ``value`` is a ``kind``."""
    if not isinstance(value, kind):
        raise ParameterError(name, f"{name} must be a {kind.__name__}, got {value!r}")


def parameter_of(field: attrs.Attribute) -> Parameter | None:
    """The declaration of an attrs field made with :meth:`Parameter.field`, if any."""
    found = field.metadata.get("parameter")
    return found if isinstance(found, Parameter) else None


def declared_settings(cls: type) -> dict[str, Parameter]:
    """The settings of an attrs plug-in class by name: each field's declaration, or for a
    field without one, a declaration from its name and type (parsed as JSON)."""
    if not attrs.has(cls):
        return {}
    settings = {}
    for field in attrs.fields(cls):
        if not field.init:
            continue
        declared = parameter_of(field)
        if declared is None:
            default = NO_DEFAULT if field.default is attrs.NOTHING else field.default
            declared = Parameter(
                field.name, f"setting {field.name}", default=default, convert=json_literal
            )
        settings[field.name] = declared
    return settings


def json_literal(value: Any) -> Any:
    """An undeclared setting given as text: a JSON literal, else the text itself
    (``RK23``). JSON beyond untrusted.load_json's bounds (nesting, integer digits, a key
    given twice, NaN) is a one-line ParameterError, never a traceback or a key that
    silently wins."""
    if not isinstance(value, str):
        return value
    return load_json(value, "setting", _setting_error, text_if_not_json=True)


def _setting_error(message: str) -> ParameterError:
    return ParameterError("setting", message)
