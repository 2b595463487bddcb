"""Plug-in discovery: pluggy registers classes by name; lookups are plain dict reads."""

from __future__ import annotations

import functools
from collections.abc import Iterable
from typing import Any

import pluggy

from . import hookspecs
from .batch import CORE_COLUMNS
from .errors import ParameterError, PluginError, UnknownNameError
from .failure import FailureModel
from .integrator import Integrator
from .parameters import Parameter
from .plugin import Plugin
from .resistance import ResistanceLaw

#: The kinds of plug-in, by the word users and the CLI use for them (the model's slots).
KINDS: dict[str, type[Plugin]] = {
    "resistance": ResistanceLaw,
    "failure": FailureModel,
    "integrator": Integrator,
}


class PluginRegistry:
    """Name → class tables, one per kind of plug-in, and the plate constants they declare.

    Registering checks a class's declarations: a plate constant may be declared by several
    plug-ins only with equal declarations, so that a plate's ``a`` means one thing
    whatever model reads it; a plug-in's settings, plate constants and prepared columns
    may not share a name.
    """

    def __init__(self) -> None:
        self._classes: dict[str, dict[str, type[Plugin]]] = {kind: {} for kind in KINDS}
        self._origin: dict[tuple[str, str], str] = {}
        self._constants: dict[str, tuple[Parameter, list[str]]] = {}

    def add(self, cls: type) -> None:
        """Register a concrete ResistanceLaw, FailureModel or Integrator subclass."""
        kinds = [k for k, base in KINDS.items() if isinstance(cls, type) and issubclass(cls, base)]
        if len(kinds) != 1:
            raise PluginError(f"{cls!r} is not a ResistanceLaw, FailureModel or Integrator")
        name = getattr(cls, "name", None)
        if not isinstance(name, str) or not name:
            raise PluginError(f"{cls.__qualname__} ({cls.__module__}) has no 'name'")
        kind = kinds[0]
        plugin: type[Plugin] = cls
        label = f"{kind} {name!r} ({cls.__module__})"
        if name in self._classes[kind] and self._classes[kind][name] is not cls:
            raise PluginError(
                f"{kind} {name!r} is registered twice: by {self._origin[kind, name]} "
                f"and by {cls.__module__}"
            )
        self._check_declarations(plugin, label)
        for declared in plugin.plate_constants:
            entry = self._constants.setdefault(declared.name, (declared, []))
            entry[1].append(f"{kind} {name}")
        self._classes[kind][name] = plugin
        self._origin[kind, name] = plugin.__module__

    def _check_declarations(self, cls: type[Plugin], label: str) -> None:
        constants = list(cls.plate_constants)
        if not all(isinstance(p, Parameter) for p in constants):
            raise PluginError(f"{label}: plate_constants must be Parameter declarations")
        settings = set(cls.setting_declarations())
        names = [p.name for p in constants]
        columns = [c.name for c in cls.columns]
        for group in (names, columns):
            if len(set(group)) != len(group):
                raise PluginError(f"{label} declares a name twice: {sorted(group)}")
        clash = (set(names) & settings) | (set(columns) & (settings | set(names)))
        clash |= (set(names) | set(columns)) & set(CORE_COLUMNS)
        if clash:
            raise PluginError(f"{label} uses the name {sorted(clash)[0]!r} for two things")
        for declared in constants:
            known = self._constants.get(declared.name)
            if known is not None and known[0] != declared:
                raise PluginError(
                    f"{label} declares plate constant {declared.name!r} unlike "
                    f"{', '.join(known[1])}: declare the same Parameter object"
                )

    @property
    def plate_constants(self) -> dict[str, Parameter]:
        """Every plate constant a registered plug-in declares, by name."""
        return {name: declared for name, (declared, _) in self._constants.items()}

    def declared_by(self, constant: str) -> list[str]:
        """The plug-ins (``"failure plugging"``) that declare a plate constant."""
        return list(self._constants.get(constant, (None, []))[1])

    def names(self, kind: str) -> list[str]:
        """Registered names of one kind, sorted."""
        return sorted(self._classes[kind])

    def get(self, kind: str, name: str) -> type[Plugin]:
        """The class registered as ``name``; UnknownNameError lists the choices."""
        try:
            return self._classes[kind][name]
        except KeyError:
            choices = ", ".join(self.names(kind)) or "none registered"
            raise UnknownNameError(f"unknown {kind} {name!r}; choose from: {choices}") from None

    def create(self, kind: str, name: str, **settings: Any) -> Any:
        """An instance of the ``name`` plug-in with ``settings`` [SI].

        Unknown settings, and settings a plug-in rejects, raise ParameterError.
        """
        cls = self.get(kind, name)
        known = cls.setting_declarations()
        unknown = sorted(set(settings) - set(known))
        if unknown:
            allowed = ", ".join(sorted(known)) or "none"
            raise ParameterError(
                unknown[0], f"{kind} {name!r} has no setting {unknown[0]!r}; settings: {allowed}"
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
