"""Attributes read from an archive, typed: what someone else wrote, checked before use.

An archive's attributes are sealed by a digest (``attributes_sha256``), but anyone who
edits them can recompute it, so a sealed value is still untrusted input. Each reader
here returns the value the format says (text, a number, a JSON object or list of the
right shape) or raises a one-line :class:`~plateimpact.base.errors.ArchiveError` naming the
attribute: JSON goes through :func:`plateimpact.base.untrusted.load_json` (depth, size, integer
digits, duplicate keys, NaN), never ``json.loads``.
"""

from __future__ import annotations

import math
from collections.abc import Mapping
from typing import Any

from ..base.errors import ArchiveError, PlateImpactError
from ..base.untrusted import load_json, printable
from ..run.variant import Variant

#: Run attributes holding a JSON object, and those holding text.
JSON_OBJECTS = ("variant", "model", "versions", "failure_state_units")
#: JSON objects a run may lack: the code that made it (``plugins``: runs made before
#: plateimpact recorded it have none; docs/archive.md, "Provenance").
OPTIONAL_JSON_OBJECTS = ("plugins",)
TEXTS = ("git_commit", "host", "start_time", "end_time")


def _kind(value: object) -> str:
    names: dict[type, str] = {dict: "an object", list: "a list", str: "text"}
    return names.get(type(value), printable(type(value).__name__))


def text(attributes: Mapping[str, object], key: str, what: str) -> str:
    """The text attribute ``key`` (bytes are read as UTF-8)."""
    if key not in attributes:
        raise ArchiveError(f"{what}: attribute {key} is missing; the archive is damaged")
    value = attributes[key]
    if isinstance(value, bytes):
        try:
            return value.decode()
        except UnicodeDecodeError:
            raise ArchiveError(f"{what}: attribute {key} is not UTF-8 text") from None
    if not isinstance(value, str):
        raise ArchiveError(
            f"{what}: attribute {key} is {printable(type(value).__name__)}, not text; the "
            "archive is damaged"
        )
    return value


def number(attributes: Mapping[str, object], key: str, what: str) -> float:
    """The finite number attribute ``key``."""
    value = attributes.get(key)
    if isinstance(value, bool) or not isinstance(value, int | float) or not math.isfinite(value):
        raise ArchiveError(
            f"{what}: attribute {key} is {printable(repr(value), 40)}, not a finite number; "
            "the archive is damaged"
        )
    return float(value)


def json_value(attributes: Mapping[str, object], key: str, what: str, kind: type) -> Any:
    """The JSON attribute ``key``, which must hold a ``kind`` (dict or list)."""
    found = load_json(text(attributes, key, what), f"{what}: attribute {key}", ArchiveError)
    if not isinstance(found, kind):
        raise ArchiveError(
            f"{what}: attribute {key} holds {_kind(found)}, not {_kind(kind())}; the archive "
            "is damaged"
        )
    return found


def variant(value: object, what: str) -> Variant:
    """A variant from its stored object (name, plug-ins, settings)."""
    if not isinstance(value, dict):
        raise ArchiveError(f"{what}: a variant is {_kind(value)}, not an object")
    try:
        return Variant(**value)
    except (TypeError, ValueError, PlateImpactError) as exc:
        reason = str(exc).splitlines()[0] if str(exc) else type(exc).__name__
        raise ArchiveError(
            f"{what}: not a variant this plateimpact reads ({printable(reason, 160)})"
        ) from None


def run_variant(attributes: Mapping[str, object], what: str) -> Variant:
    """The variant a run records (attribute ``variant``)."""
    return variant(json_value(attributes, "variant", what, dict), f"{what}: attribute variant")


def study_variants(attributes: Mapping[str, object], what: str) -> tuple[Variant, ...]:
    """A study's variants (attribute ``variants``, a list of objects)."""
    found = json_value(attributes, "variants", what, list)
    return tuple(variant(v, f"{what}: attribute variants") for v in found)


def plate_labels(attributes: Mapping[str, object], what: str) -> list[str]:
    """A study's plate labels (attribute ``plate_labels``, a list of text)."""
    found = json_value(attributes, "plate_labels", what, list)
    if not all(isinstance(label, str) for label in found):
        raise ArchiveError(f"{what}: attribute plate_labels is not a list of text")
    return found


def run_metadata(attributes: Mapping[str, object], what: str) -> dict[str, object]:
    """A run's attributes, JSON decoded and typed: the JSON objects, the texts and the
    wall time each as the format says (the data file's own labels left out)."""
    out: dict[str, object] = {}
    for key, value in attributes.items():
        if key in ("Conventions", "title", "history", "featureType", "study", "run"):  # its labels
            continue
        out[key] = value
    for key in JSON_OBJECTS:
        out[key] = json_value(attributes, key, what, dict)
    for key in OPTIONAL_JSON_OBJECTS:
        if key in attributes:
            out[key] = json_value(attributes, key, what, dict)
    for key in TEXTS:
        out[key] = text(attributes, key, what)
    out["wall_time_s"] = number(attributes, "wall_time_s", what)
    return out
