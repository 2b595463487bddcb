"""What someone else wrote: JSON read within bounds, text made safe for a terminal.

Anything read from a file (an archive's attributes, a plate file, an inputs record, a
shot file, a P* table) may come from a colleague's machine or a hostile one. Two rules:

* :func:`load_json` parses JSON into plain values or raises the caller's one-line
  :class:`~plateimpact.base.errors.PlateImpactError`: never a ``RecursionError`` from deep
  nesting, never an integer too long to become a float, never a key that silently wins
  over its duplicate, never ``NaN`` (``Infinity`` is JSON's spelling of P* = inf and is
  read).
* :func:`printable` escapes whatever a terminal would act on (escape sequences, carriage
  returns, new lines that would forge a ``plateimpact: error:`` line, bidirectional
  overrides) before text from a file is printed.
"""

from __future__ import annotations

import json
import os
import stat
from collections.abc import Callable
from typing import Any

from .errors import PlateImpactError

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


#: What makes the caller's error from a one-line message: an error class taking the
#: message alone, or a function (``lambda m: ParameterError("variant", m)``).
ErrorFactory = Callable[[str], PlateImpactError]


def load_json(
    text: str | bytes,
    what: str,
    error: ErrorFactory = PlateImpactError,
    *,
    max_bytes: int = MAX_BYTES,
    text_if_not_json: bool = False,
) -> Any:
    """The JSON value in ``text``, read from ``what`` (named in messages: a file, an
    attribute); any malformed, oversized, too deeply nested, duplicate-keyed or NaN
    content raises ``error`` with one line.

    ``text_if_not_json``: for a value that may be JSON or plain text (``--set
    integrator.method=RK23``): text that is no JSON at all, and does not open an array
    or object, is returned as it is; JSON beyond the bounds is still refused."""
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

    def too_long(digits: int, key: str | None) -> PlateImpactError:
        where = f"{printable(key, 80)}: " if key is not None else ""
        return error(
            f"{what}: {where}an integer of {digits} digits (at most {MAX_INTEGER_DIGITS} are read)"
        )

    def pairs(items: list[tuple[str, Any]]) -> dict[str, Any]:
        out: dict[str, Any] = {}
        for key, value in items:
            if key in out:
                raise error(f"{what}: key {printable(key)!r} appears twice")
            overlong = _overlong(value)
            if overlong is not None:  # named by its key: the reader's message would
                raise too_long(overlong.digits, key)
            out[key] = value
        return out

    def integer(literal: str) -> int | _Overlong:
        digits = len(literal.lstrip("-"))
        return _Overlong(digits) if digits > MAX_INTEGER_DIGITS else int(literal)

    def constant(name: str) -> float:
        if name == "NaN":
            raise error(f"{what}: NaN is not a value")
        return float(name)  # Infinity, -Infinity

    try:
        value = json.loads(
            text, object_pairs_hook=pairs, parse_int=integer, parse_constant=constant
        )
    except ValueError as exc:  # JSONDecodeError is one
        if isinstance(exc, PlateImpactError):
            raise
        if text_if_not_json and isinstance(exc, json.JSONDecodeError):
            if text.lstrip()[:1] not in ("[", "{"):
                return text
        reason = str(exc).splitlines()[0] if str(exc).strip() else type(exc).__name__
        raise error(f"{what}: not valid JSON: {printable(reason)}") from None
    except RecursionError:  # belt and braces: _too_deep should have caught it
        raise error(f"{what}: JSON nested too deeply") from None
    overlong = _overlong(value)  # outside any object: the value itself, or an array's
    if overlong is not None:
        raise too_long(overlong.digits, None)
    return value


def load_json_file(
    path: str | os.PathLike[str],
    error: ErrorFactory = PlateImpactError,
    *,
    max_bytes: int = MAX_BYTES,
) -> Any:
    """The JSON value in the file at ``path``, as :func:`load_json` reads it (at most
    ``max_bytes`` are read, never the whole of a huge file); a file that cannot be read
    is ``error`` too, naming it (printable, cut to 200 characters)."""
    what = printable(os.fspath(path), 200)
    check_input(path, what, error)
    try:
        with open(path, "rb") as handle:
            data = handle.read(max_bytes + 1)
    except OSError as exc:
        raise error(f"{what}: cannot read: {exc.strerror or type(exc).__name__}") from None
    except ValueError as exc:  # a NUL in the path
        raise error(f"{what}: cannot read: {exc}") from None
    return load_json(data, what, error, max_bytes=max_bytes)


def check_input(path: str | os.PathLike[str], what: str, error: ErrorFactory) -> None:
    """Refuse, before it is opened, an input file that could hang its reader or is no
    file at all: a named pipe (FIFO), whose open waits for a writer that may never come,
    and a device node (a terminal waits for typing; a disk is no shot file), either of
    which a tarball can ship under an ordinary name. A pipe the shell hands over
    (``<(gunzip -c f.gz)``, ``/dev/stdin``) is reached through a link in ``/dev/fd`` and
    is read as usual; a path that cannot be examined is left to the open, which says
    why."""
    try:
        mode = os.lstat(path).st_mode
    except (OSError, ValueError):
        return
    if stat.S_ISFIFO(mode):
        raise error(
            f"{what}: a named pipe (FIFO), whose reading would wait for a writer; give a "
            "regular file (or a pipe from the shell, <(command))"
        )
    if stat.S_ISCHR(mode) or stat.S_ISBLK(mode):
        raise error(f"{what}: a device, not a file; give a regular file")


class _Overlong:
    """An integer literal of more digits than are read, until its key is known."""

    def __init__(self, digits: int) -> None:
        self.digits = digits


def _overlong(value: Any) -> _Overlong | None:
    """The first over-long integer in ``value`` or in its arrays (objects were checked
    when they were made), depth-first; bounded by :data:`MAX_DEPTH`."""
    if isinstance(value, _Overlong):
        return value
    if isinstance(value, list):
        for item in value:
            found = _overlong(item)
            if found is not None:
                return found
    return None


def quoted(value: object, limit: int = 60) -> str:
    """A value read from a file, for a message: its JSON, inert, cut to ``limit``."""
    try:
        text = json.dumps(value)
    except (TypeError, ValueError):
        text = repr(value)
    return printable(text, limit)


def described(value: object) -> str:
    """What a value read from a file is, for a message: ``true``, ``null``, ``the string
    "5"``, ``an array``, ``an object``, or the number (never the whole of a large one)."""
    if isinstance(value, bool) or value is None:
        return json.dumps(value)
    if isinstance(value, str):
        return f"the string {quoted(value)}"
    if isinstance(value, list):
        return f"an array of {len(value)}"
    if isinstance(value, dict):
        return "an object"
    return quoted(value)


#: What a spreadsheet reads as the start of a formula in a CSV cell.
FORMULA_STARTS = ("=", "+", "-", "@", "\t", "\r")


def spreadsheet_safe(cell: str) -> str:
    """A text cell of a CSV file that a spreadsheet will not run: text from someone
    else's file (a plate label, a material, a shot's source) that begins as a formula
    does (``=HYPERLINK(...)``, ``@SUM``, ``+``, ``-``) gets a leading ``'``, which
    spreadsheets show as text (the OWASP rule for CSV injection); a number (``-1.5``)
    and every other cell are written as they are."""
    if not cell.startswith(FORMULA_STARTS):
        return cell
    try:
        float(cell)
    except ValueError:
        return "'" + cell
    return cell


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
