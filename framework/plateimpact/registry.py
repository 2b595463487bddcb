"""Plug-in discovery: pluggy registers classes by name; lookups are plain dict reads."""

from __future__ import annotations

import functools
from collections.abc import Iterable
from typing import Any

import attrs
import pluggy

from . import hookspecs
from .errors import ParameterError, UnknownNameError
from .failure import FailureModel
from .integrator import Integrator
from .resistance import ResistanceLaw

#: The kinds of plug-in, by the word users and the CLI use for them.
KINDS: dict[str, type] = {
    "resistance": ResistanceLaw,
    "failure": FailureModel,
    "integrator": Integrator,
}


class PluginRegistry:
    """Name → class tables, one per kind of plug-in."""

    def __init__(self) -> None:
        self._classes: dict[str, dict[str, type]] = {kind: {} for kind in KINDS}
        self._origin: dict[tuple[str, str], str] = {}

    def add(self, cls: type) -> None:
        """Register a concrete ResistanceLaw, FailureModel or Integrator subclass."""
        kinds = [k for k, base in KINDS.items() if isinstance(cls, type) and issubclass(cls, base)]
        if len(kinds) != 1:
            raise TypeError(f"{cls!r} is not a ResistanceLaw, FailureModel or Integrator")
        name = getattr(cls, "name", None)
        if not isinstance(name, str) or not name:
            raise TypeError(f"{cls.__qualname__} has no 'name'")
        kind = kinds[0]
        if name in self._classes[kind] and self._classes[kind][name] is not cls:
            raise ValueError(
                f"{kind} {name!r} is registered twice: by {self._origin[kind, name]} "
                f"and by {cls.__module__}"
            )
        self._classes[kind][name] = cls
        self._origin[kind, name] = cls.__module__

    def names(self, kind: str) -> list[str]:
        """Registered names of one kind, sorted."""
        return sorted(self._classes[kind])

    def get(self, kind: str, name: str) -> type:
        """The class registered as ``name``; UnknownNameError lists the choices."""
        try:
            return self._classes[kind][name]
        except KeyError:
            choices = ", ".join(self.names(kind)) or "none registered"
            raise UnknownNameError(f"unknown {kind} {name!r}; choose from: {choices}") from None

    def create(self, kind: str, name: str, **settings: Any) -> Any:
        """An instance of the ``name`` plug-in with ``settings``.

        Unknown settings, and settings a plug-in rejects, raise ParameterError.
        """
        cls = self.get(kind, name)
        if attrs.has(cls):
            known = {f.name for f in attrs.fields(cls) if f.init}
            unknown = sorted(set(settings) - known)
            if unknown:
                allowed = ", ".join(sorted(known)) or "none"
                raise ParameterError(
                    unknown[0],
                    f"{kind} {name!r} has no setting {unknown[0]!r}; settings: {allowed}",
                )
        try:
            return cls(**settings)
        except TypeError as exc:
            raise ParameterError(name, f"{kind} {name!r}: {exc}") from None


def load_registry(*, entry_points: bool = True, plugins: Iterable[object] = ()) -> PluginRegistry:
    """A registry filled by the ``plateimpact_register`` hooks.

    Parameters
    ----------
    entry_points : bool
        Load the installed packages of the ``plateimpact`` entry-point group (the
        built-ins and any third-party package). False gives a registry of ``plugins``
        only, which keeps a test independent of what else is installed.
    plugins : iterable of modules or objects
        Extra hook implementations to register directly.
    """
    manager = pluggy.PluginManager(hookspecs.PROJECT)
    manager.add_hookspecs(hookspecs)
    if entry_points:
        manager.load_setuptools_entrypoints(hookspecs.PROJECT)
    for plugin in plugins:
        manager.register(plugin)
    manager.check_pending()
    registry = PluginRegistry()
    manager.hook.plateimpact_register(registry=registry)
    return registry


@functools.cache
def default_registry() -> PluginRegistry:
    """The registry of every installed plug-in package, loaded on first request."""
    return load_registry()
