"""What someone else wrote: JSON read within bounds, text made safe for a terminal.

Anything read from a file (an archive's attributes, a plate file, an inputs record, a
shot file, a P* table) may come from a colleague's machine or a hostile one. Two rules:

* :func:`load_json` parses JSON into plain values or raises the caller's one-line
  :class:`~plateimpact.errors.PlateImpactError`: never a ``RecursionError`` from deep
  nesting, never an integer too long to become a float, never a key that silently wins
  over its duplicate, never ``NaN`` (``Infinity`` is JSON's spelling of P* = inf and is
  read).
* :func:`printable` escapes whatever a terminal would act on (escape sequences, carriage
  returns, new lines that would forge a ``plateimpact: error:`` line, bidirectional
  overrides) before text from a file is printed.
"""

from __future__ import annotations

import json
from typing import Any

from ..errors import PlateImpactError

#: Deepest nesting of arrays and objects accepted. Every format plateimpact reads nests
#: at most 4 deep (an inputs record's model settings holding a P* table's rows).
MAX_DEPTH = 32
#: Longest integer literal accepted [digits]: counts and indices need far fewer, and a
#: longer one cannot become a float (10**309 overflows).
MAX_INTEGER_DIGITS = 18
#: Largest JSON text accepted [bytes]: a plate file or inputs record is a few kB.
MAX_BYTES = 16 << 20


def _too_deep(text: str, limit: int) -> bool:
    """Whether arrays and objects in ``text`` nest deeper than ``limit`` (strings and
    their escapes skipped), found without recursion."""
    depth, inside, escaped = 0, False, False
    for char in text:
        if inside:
            if escaped:
                escaped = False
            elif char == "\\":
                escaped = True
            elif char == '"':
                inside = False
        elif char == '"':
            inside = True
        elif char in "[{":
            depth += 1
            if depth > limit:
                return True
        elif char in "]}":
            depth -= 1
    return False


def load_json(
    text: str | bytes,
    what: str,
    error: type[PlateImpactError] = PlateImpactError,
    *,
    max_bytes: int = MAX_BYTES,
) -> Any:
    """The JSON value in ``text``, read from ``what`` (named in messages: a file, an
    attribute); any malformed, oversized, too deeply nested, duplicate-keyed or NaN
    content raises ``error`` with one line."""
    if isinstance(text, bytes | bytearray):
        if len(text) > max_bytes:
            raise error(f"{what}: {len(text):,} bytes of JSON, more than the {max_bytes:,} read")
        try:
            text = bytes(text).decode("utf-8-sig")
        except UnicodeDecodeError as exc:
            raise error(f"{what}: not UTF-8 text ({exc.reason} at byte {exc.start})") from None
    if len(text) > max_bytes:
        raise error(f"{what}: {len(text):,} characters of JSON, more than the {max_bytes:,} read")
    if _too_deep(text, MAX_DEPTH):
        raise error(f"{what}: JSON nested more than {MAX_DEPTH} deep")

    def pairs(items: list[tuple[str, Any]]) -> dict[str, Any]:
        out: dict[str, Any] = {}
        for key, value in items:
            if key in out:
                raise error(f"{what}: key {printable(key)!r} appears twice")
            out[key] = value
        return out

    def integer(literal: str) -> int:
        if len(literal.lstrip("-")) > MAX_INTEGER_DIGITS:
            raise error(
                f"{what}: an integer of {len(literal.lstrip('-'))} digits (at most "
                f"{MAX_INTEGER_DIGITS} are read)"
            )
        return int(literal)

    def constant(name: str) -> float:
        if name == "NaN":
            raise error(f"{what}: NaN is not a value")
        return float(name)  # Infinity, -Infinity

    try:
        return json.loads(text, object_pairs_hook=pairs, parse_int=integer, parse_constant=constant)
    except ValueError as exc:  # JSONDecodeError is one
        if isinstance(exc, PlateImpactError):
            raise
        reason = str(exc).splitlines()[0] if str(exc).strip() else type(exc).__name__
        raise error(f"{what}: not valid JSON: {printable(reason)}") from None
    except RecursionError:  # belt and braces: _too_deep should have caught it
        raise error(f"{what}: JSON nested too deeply") from None


def printable(text: object, limit: int | None = None) -> str:
    """``text`` with every character a terminal would act on or hide escaped as Python
    writes it (``\\x1b``, ``\\n``, ``\\u202e``), so that it prints as one inert line;
    cut to ``limit`` characters (with "...") if given."""
    string = str(text)
    if not string.isprintable():
        string = "".join(c if c.isprintable() else repr(c)[1:-1] for c in string)
    if limit is not None and len(string) > limit:
        string = string[: max(limit - 3, 0)] + "..."
    return string
