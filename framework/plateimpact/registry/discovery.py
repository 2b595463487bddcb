"""Installed packages' entry points, read one distribution at a time.

``importlib.metadata.entry_points()`` parses every installed distribution's
``entry_points.txt`` at once, so one malformed file stops discovery for all of them; and
an entry point that raises on import would stop whoever loads it. Here each distribution
and each entry point is read on its own, and whatever fails becomes a
:class:`BrokenPackage` record, to be reported and skipped, never raised.
"""

from __future__ import annotations

import re
from collections.abc import Iterator
from importlib import metadata

import attrs


def first_line(exc: BaseException) -> str:
    """``"Type: first line of the message"``, or the type alone for an empty message."""
    lines = str(exc).strip().splitlines()
    return f"{type(exc).__name__}: {lines[0]}" if lines else type(exc).__name__


@attrs.frozen
class BrokenPackage:
    """An installed package whose entry point failed to load, and why (it was skipped).

    Attributes
    ----------
    distribution : str
        The distribution's name and version, ``"plateimpact-broken 0.1"``.
    entry_point : str
        The entry point as declared, ``"broken = plateimpact_broken"``.
    error : str
        The exception's type and the first line of its message.
    provides : tuple of (kind, name)
        The plug-ins its hook tried to register before it failed (empty when it failed
        earlier), so that asking for one of them can say why it is missing.
    """

    distribution: str
    entry_point: str
    error: str
    provides: tuple[tuple[str, str], ...] = ()

    def describe(self) -> str:
        """One line: the distribution, the entry point and the error."""
        return f"{self.distribution} (entry point {self.entry_point}): {self.error}"


def distribution_label(dist: metadata.Distribution | None) -> str:
    """``"name version"`` of a distribution, as far as its metadata can tell."""
    if dist is None:
        return "an unknown distribution"
    try:
        return f"{dist.metadata['Name'] or 'unnamed'} {dist.version or '(no version)'}"
    except Exception:  # unreadable METADATA: still name something
        return f"the distribution at {getattr(dist, '_path', '?')}"


def entry_point_label(entry: metadata.EntryPoint) -> str:
    return f"{entry.name} = {entry.value}"


def distribution_name(dist: metadata.Distribution | None) -> str:
    """The distribution's name, normalized (``plateimpact-isotropic``); "" if unknown."""
    try:
        name = dist.metadata["Name"] if dist is not None else None
    except Exception:  # unreadable METADATA
        name = None
    return re.sub(r"[-_.]+", "-", name).lower() if name else ""


def distribution_version(dist: metadata.Distribution | None) -> str:
    """The distribution's version as its metadata says; "" if unknown."""
    try:
        version = dist.version if dist is not None else None
    except Exception:  # unreadable METADATA
        version = None
    return version if isinstance(version, str) else ""


@attrs.frozen
class PluginOrigin:
    """Where an installed plug-in class came from: the distribution (its name as its
    metadata spells it, and version) and the entry point it was registered through,
    ``"builtin = plateimpact_plugins"``; "" where the metadata does not say."""

    distribution: str
    version: str
    entry_point: str

    @classmethod
    def of(cls, entry: metadata.EntryPoint) -> PluginOrigin:
        dist = entry.dist
        try:
            name = dist.metadata["Name"] if dist is not None else None
        except Exception:  # unreadable METADATA
            name = None
        return cls(name or "", distribution_version(dist), entry_point_label(entry))


def installed_entry_points(group: str) -> Iterator[metadata.EntryPoint | BrokenPackage]:
    """The entry points of ``group``, each distribution once (the first on ``sys.path``,
    as importlib.metadata chooses); a distribution whose ``entry_points.txt`` declares
    the group but cannot be parsed comes as a :class:`BrokenPackage`. A malformed file
    that does not mention ``group`` is another program's business and is passed over.
    """
    header = re.compile(rf"^\s*\[\s*{re.escape(group)}\s*\]\s*$", re.M)
    seen: set[str] = set()
    for dist in metadata.distributions():
        try:
            text = dist.read_text("entry_points.txt")
        except Exception:  # an unreadable file: as if absent, unless parsing says more
            text = None
        if not text or not header.search(text):
            continue
        key = distribution_name(dist)
        if key and key in seen:  # shadowed by an earlier copy on the path
            continue
        seen.add(key)
        try:
            entries = list(dist.entry_points.select(group=group))
        except Exception as exc:
            label = distribution_label(dist)
            yield BrokenPackage(label, f"[{group}] in entry_points.txt", first_line(exc))
            continue
        yield from entries
