"""Which code computed a result: each plug-in's distribution, version and source hash, and
the core's (docs/archive.md, "Provenance"). Runs, sweeps, limits and maps record it as
``plugins``; a resumed study keeps a stored run only if its record matches the code it
would run now (study.reruns).

Hashes are computed once per plug-in class and once for the core, per process, on the
first record asked for, never per run or scene.
"""

from __future__ import annotations

import functools
import weakref
from collections.abc import Iterable, Mapping
from importlib import metadata as importlib_metadata
from typing import Any

from ..base.untrusted import printable
from ..model.plugin import Plugin
from ..registry.plugin_registry import KINDS, plugin_origin
from ..run.simulation import Simulation
from .source_hash import module_sources, source_sha256

#: The core's distribution, and the module whose imports, transitively, are the core
#: code every run executes (the model, its events, the driver, the results).
CORE, CORE_ROOT = "plateimpact", "plateimpact.run.simulation"
#: The limits finder: what places a boundary and builds a map from the scenes it runs
#: (a limits record's ``limits`` entry).
LIMITS_ROOTS, LIMITS_PACKAGE = (
    ("plateimpact.limits.plate_limits", "plateimpact.limits.maps"),
    "plateimpact.limits",
)
#: The built-in plug-ins' package, whose shared declarations (plate constants) third-party
#: plug-ins import: its modules count in the hash of a plug-in that imports them.
BUILTINS = "plateimpact_plugins"
#: The slots of a record, and what is compared on resume in each (what, changed, could
#: change a result; the entry point's name and the module list are only reported).
SLOTS = ("core", *KINDS)
COMPARED = ("name", "version", "class", "distribution", "distribution_version", "source_sha256")
#: Hex digits of a hash shown in messages and by ``show``.
SHORT = 12

_RECORDS: weakref.WeakKeyDictionary[type, dict[str, Any]] = weakref.WeakKeyDictionary()


def _hashed(roots: tuple[str, ...], followed: Iterable[str]) -> dict[str, Any]:
    sources = module_sources(roots, followed)
    return {
        "source_sha256": source_sha256(sources),
        "source_modules": [name for name, _ in sources],
    }


@functools.cache
def core_record() -> dict[str, Any]:
    """The core's distribution, version and source hash."""
    try:
        version: str | None = importlib_metadata.version(CORE)
    except importlib_metadata.PackageNotFoundError:  # a source tree on the path
        version = None
    return {"distribution": CORE, "version": version, **_hashed((CORE_ROOT,), [CORE])}


@functools.cache
def limits_record() -> dict[str, Any]:
    """The limits finder's source hash (its modules in plateimpact.limits)."""
    return _hashed(LIMITS_ROOTS, [LIMITS_PACKAGE])


def plugin_record(cls: type[Plugin]) -> dict[str, Any]:
    """A plug-in class's name, version, distribution, entry point and source hash (its
    module and what it imports from its own top-level package and from the built-ins'),
    computed once per class."""
    known = _RECORDS.get(cls)
    origin = plugin_origin(cls)
    where = {
        "distribution": origin.distribution or None if origin else None,
        "distribution_version": origin.version or None if origin else None,
        "entry_point": origin.entry_point or None if origin else None,
    }
    if known is None:
        followed = {cls.__module__.partition(".")[0], BUILTINS} - {CORE}
        known = _RECORDS[cls] = {
            "name": cls.name,
            "version": cls.version,
            "class": f"{cls.__module__}.{cls.__qualname__}",
            **_hashed((cls.__module__,), followed),
        }
    return {**known, **where}  # the origin as last loaded: what is installed now


def plugins_record(simulation: Simulation) -> dict[str, dict[str, Any]]:
    """The ``plugins`` record of what ``simulation`` runs: ``core`` and one entry per slot
    (``resistance``, ``failure``, ``integrator``)."""
    model = simulation.model
    used = {"resistance": model.resistance, "failure": model.failure}
    used["integrator"] = simulation.integrator
    return {"core": core_record(), **{kind: plugin_record(type(used[kind])) for kind in KINDS}}


def changes(stored: object, current: Mapping[str, Mapping[str, Any]]) -> list[str]:
    """What differs between a stored ``plugins`` record (untrusted: any JSON value) and
    ``current``, one phrase per slot that differs; a record that cannot say (absent,
    malformed, a source hash unknown) differs. Empty: the same code."""
    if not isinstance(stored, Mapping):
        return ["no plug-in provenance recorded"]
    found = []
    for slot, new in current.items():
        old = stored.get(slot)
        label = f"{slot} {new['name']}" if "name" in new else slot
        if not isinstance(old, Mapping):
            found.append(f"{label}: not recorded")
            continue
        parts = []
        for key in COMPARED:
            if key not in new:
                continue
            if key == "source_sha256" and (old.get(key) is None or new[key] is None):
                parts.append(f"source unknown (recorded {_short(old.get(key))}, "
                             f"now {_short(new[key])})")  # fmt: skip
            elif old.get(key) != new[key]:
                was, now = _short(old.get(key)), _short(new[key])
                parts.append(f"{key.replace('_', ' ')} {was} -> {now}")
        if parts:
            found.append(f"{label}: {', '.join(parts)}")
    return found


def _short(value: object) -> str:
    """A recorded value for a message: a hash shortened, text made safe to print."""
    if value is None:
        return "none"
    text = str(value)
    if len(text) == 64 and all(c in "0123456789abcdef" for c in text):
        return text[:SHORT]
    return printable(text, 60)


def summary(record: object) -> list[str]:
    """``show``'s lines of a stored ``plugins`` record (untrusted), one per slot:
    ``code: integrator dopri5 from plateimpact 0.1.0, source 0a7f81a21552``."""
    if not isinstance(record, Mapping):
        return ["code: no plug-in provenance recorded (written before plateimpact recorded it)"]
    lines = []
    for slot in SLOTS:  # a limits record's "limits" hash is the finder's, not a plug-in's
        entry = record.get(slot)
        if not isinstance(entry, Mapping):
            lines.append(f"code: {slot} not recorded")
            continue
        source = entry.get("source_sha256")
        source = "unknown (not all of it in files)" if source is None else _short(source)
        if slot == "core":
            origin = f"{_short(entry.get('distribution'))} {_short(entry.get('version'))}"
            lines.append(f"code: core {origin}, source {source}")
            continue
        origin = "not from an installed package"
        if entry.get("distribution") is not None:
            version = _short(entry.get("distribution_version"))
            origin = f"from {_short(entry.get('distribution'))} {version}"
        lines.append(f"code: {slot} {_short(entry.get('name'))} {origin}, source {source}")
    return lines
