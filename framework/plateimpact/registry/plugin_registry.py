"""Plug-in discovery: pluggy registers classes by name; lookups are plain dict reads.

Installed packages are loaded one at a time: a package that fails to load (an import
error, a misspelled or failing hook, a class the registry refuses) is skipped, with one
warning naming it, and recorded in :attr:`PluginRegistry.broken`; the others, built-ins
included, keep working. Plug-ins handed to :func:`load_registry` directly are the
caller's own code and fail loudly instead.
"""

from __future__ import annotations

import contextlib
import functools
import warnings
import weakref
from collections.abc import Iterable, Iterator
from typing import Any

import pluggy

from ..base.errors import (
    ParameterError,
    PlateImpactError,
    PluginError,
    PluginLoadWarning,
    UnknownNameError,
)
from ..base.parameters import Parameter
from ..model.batch import CORE_COLUMNS
from ..model.failure import FailureModel
from ..model.plugin import Plugin
from ..model.resistance import ResistanceLaw
from ..solve.integrator import Integrator
from . import hookspecs
from .choices import Choices
from .discovery import (
    BrokenPackage,
    PluginOrigin,
    distribution_label,
    distribution_name,
    entry_point_label,
    first_line,
    installed_entry_points,
)

#: The kinds of plug-in, by the word users and the CLI use for them (the model's slots).
KINDS: dict[str, type[Plugin]] = {
    "resistance": ResistanceLaw,
    "failure": FailureModel,
    "integrator": Integrator,
}


#: Each installed plug-in class's origin, whichever registry loaded it (provenance reads
#: it from the class a simulation holds). Weak: a class dropped by its module goes too.
_ORIGINS: weakref.WeakKeyDictionary[type, PluginOrigin] = weakref.WeakKeyDictionary()


def plugin_origin(cls: type) -> PluginOrigin | None:
    """The distribution and entry point ``cls`` was registered through; None for a
    class not registered from an installed package (handed to load_registry or
    added to a registry directly)."""
    return _ORIGINS.get(cls)


def _flag_list(kind: str, cls: type[Plugin]) -> list[tuple[str, str]]:
    """The command-line flags a plug-in declares, each with what it sets."""
    found = [(p.flag, f"{kind} setting {s}") for s, p in cls.setting_declarations().items()]
    found += [(p.flag, f"plate constant {p.name}") for p in cls.plate_constants]
    return [(flag, meaning) for flag, meaning in found if flag]


class PluginRegistry(Choices):
    """Name → class tables, one per kind of plug-in, and the plate constants they declare;
    the defaults, presets and sphere packages declare (``plateimpact.registry.choices.Choices``).

    Registering checks a class's declarations: a plate constant may be declared by several
    plug-ins only with equal declarations, so that a plate's ``a`` means one thing
    whatever model reads it; a plug-in's settings, plate constants and prepared columns
    may not share a name; a command-line flag sets one thing. :attr:`broken` lists the
    installed packages that failed to load.
    """

    def __init__(self) -> None:
        super().__init__()
        self._classes: dict[str, dict[str, type[Plugin]]] = {kind: {} for kind in KINDS}
        self._origin: dict[tuple[str, str], str] = {}
        self._constants: dict[str, tuple[Parameter, list[str]]] = {}
        self._broken: tuple[BrokenPackage, ...] = ()
        self._attempted: list[tuple[str, str]] | None = None

    @property
    def broken(self) -> tuple[BrokenPackage, ...]:
        """The installed plug-in packages that failed to load and were skipped."""
        return self._broken

    def add(self, cls: type, *, default: bool = False) -> None:
        """Register a concrete ResistanceLaw, FailureModel or Integrator subclass; with
        ``default``, as the plug-in of its kind used when none is named (PluginError if
        another package claimed that default)."""
        kinds = [k for k, base in KINDS.items() if isinstance(cls, type) and issubclass(cls, base)]
        if len(kinds) != 1:
            raise PluginError(f"{cls!r} is not a ResistanceLaw, FailureModel or Integrator")
        name = getattr(cls, "name", None)
        if not isinstance(name, str) or not name:
            raise PluginError(f"{cls.__qualname__} ({cls.__module__}) has no 'name'")
        kind = kinds[0]
        if self._attempted is not None:
            self._attempted.append((kind, name))
        plugin: type[Plugin] = cls
        label = f"{kind} {name!r} ({cls.__module__})"
        if name in self._classes[kind] and self._classes[kind][name] is not cls:
            raise PluginError(
                f"{kind} {name!r} is registered twice: by {self._origin[kind, name]} "
                f"and by {cls.__module__}"
            )
        self._check_declarations(kind, plugin, label)
        if default:
            self._claim_default(kind, name, plugin.__module__)
        for declared in plugin.plate_constants:
            entry = self._constants.setdefault(declared.name, (declared, []))
            entry[1].append(f"{kind} {name}")
        self._classes[kind][name] = plugin
        self._origin[kind, name] = plugin.__module__

    @contextlib.contextmanager
    def _all_or_nothing(self, attempted: list[tuple[str, str]]) -> Iterator[None]:
        """Classes added inside the block stay registered only if the block completes, so
        that a package whose hook fails half-way leaves none of its classes behind (a
        package's classes may rely on each other); ``attempted`` collects the
        ``(kind, name)`` of every class the block tried to add."""
        saved = (
            {kind: dict(table) for kind, table in self._classes.items()},
            dict(self._origin),
            {name: (declared, list(users)) for name, (declared, users) in self._constants.items()},
            self._save_choices(),
        )
        self._attempted = attempted
        try:
            yield
        except BaseException:
            self._classes, self._origin, self._constants = saved[:3]
            self._restore_choices(saved[3])
            raise
        finally:
            self._attempted = None

    def _check_declarations(self, kind: str, cls: type[Plugin], label: str) -> None:
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
        self._check_flags(kind, cls, label)

    def _check_flags(self, kind: str, cls: type[Plugin], label: str) -> None:
        """A command-line flag sets one thing: a core quantity's flag is the core's, and
        two plug-ins share a flag only for the same setting or plate constant (else the
        command line could not be built, for any command)."""
        taken = {p.flag: f"the core's {p.name}" for p in CORE_COLUMNS.values() if p.flag}
        for other_kind, table in self._classes.items():
            for other in table.values():
                if other is not cls:
                    taken.update(_flag_list(other_kind, other))
        own: dict[str, str] = {}
        for flag, meaning in _flag_list(kind, cls):
            known = own.setdefault(flag, taken.get(flag, meaning))
            if known != meaning:
                raise PluginError(
                    f"{label} declares the flag {flag} for {meaning}, but {flag} sets {known}"
                )

    @property
    def plate_constants(self) -> dict[str, Parameter]:
        """Every plate constant a registered plug-in declares, by name."""
        return {name: declared for name, (declared, _) in self._constants.items()}

    def origin(self, kind: str, name: str) -> PluginOrigin | None:
        """The distribution and entry point that registered the ``name`` plug-in (see
        ``plugin_origin``)."""
        return plugin_origin(self.get(kind, name))

    def declared_by(self, constant: str) -> list[str]:
        """The plug-ins (``"failure plugging"``) that declare a plate constant."""
        return list(self._constants.get(constant, (None, []))[1])

    def _table(self, kind: str) -> dict[str, type[Plugin]]:
        if not (isinstance(kind, str) and kind in KINDS):
            choices = ", ".join(KINDS)
            raise UnknownNameError(f"unknown plug-in kind {kind!r}; choose from: {choices}")
        return self._classes[kind]

    def names(self, kind: str) -> list[str]:
        """Registered names of one kind, sorted."""
        return sorted(self._table(kind))

    def get(self, kind: str, name: str) -> type[Plugin]:
        """The class registered as ``name``; UnknownNameError lists the choices, and says
        so when the name belongs to, or might belong to, a package that failed to load."""
        table = self._table(kind)
        if isinstance(name, str) and name in table:
            return table[name]
        for package in self._broken:
            if (kind, name) in package.provides:
                raise UnknownNameError(
                    f"{kind} {name!r} is in plug-in package {package.distribution}, which "
                    f"failed to load: {package.error}"
                )
        choices = ", ".join(self.names(kind)) or "none registered"
        skipped = ""
        if self._broken:
            labels = ", ".join(package.distribution for package in self._broken)
            count = len(self._broken)
            skipped = f" ({count} plug-in package{'s' * (count > 1)} failed to load: {labels})"
        raise UnknownNameError(f"unknown {kind} {name!r}; choose from: {choices}{skipped}")

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
        except PlateImpactError:
            raise
        except (TypeError, ValueError, OverflowError) as exc:  # a setting of the wrong kind
            raise ParameterError(name, f"{kind} {name!r}: {str(exc).strip()}") from None


class HookValidationError(PluginError, pluggy.PluginValidationError):
    """A hook implementation that pluggy refuses (a misspelled hook name, an argument the
    hook does not have). Also a ``pluggy.PluginValidationError``, which is what
    :func:`load_registry` raised for it before."""


def _refused(exc: pluggy.PluginValidationError) -> HookValidationError:
    """pluggy's refusal, as one line (it spans three for an argument the hook lacks)."""
    lines = [line.strip() for line in str(exc).splitlines() if line.strip()]
    return HookValidationError(exc.plugin, "; ".join(lines))


def load_registry(*, entry_points: bool = True, plugins: Iterable[object] = ()) -> PluginRegistry:
    """A registry filled by the ``plateimpact_register`` hooks.

    Parameters
    ----------
    entry_points : bool
        Load the installed packages of the ``plateimpact`` entry-point group (the
        built-ins and any third-party package). A package that fails to load, whose hook
        is misspelled or raises, or one of whose classes the registry refuses, is
        skipped with a :class:`~plateimpact.base.errors.PluginLoadWarning` and listed in
        :attr:`PluginRegistry.broken`; none of its classes is registered. False gives a
        registry of ``plugins`` only, which keeps a test independent of what else is
        installed.
    plugins : iterable of modules or objects
        Extra hook implementations to register directly. Any problem with one of them
        raises :class:`~plateimpact.base.errors.PluginError`.
    """
    manager = pluggy.PluginManager(hookspecs.PROJECT)
    manager.add_hookspecs(hookspecs)
    # pluggy's name of each installed package -> (distribution, entry point), for reports
    installed: dict[str, tuple[str, str]] = {}
    origins: dict[str, PluginOrigin] = {}  # and where its classes come from, for provenance
    builtins: set[str] = set()  # those of plateimpact's own distribution
    broken: list[BrokenPackage] = []
    if entry_points:
        for entry in installed_entry_points(hookspecs.PROJECT):
            if isinstance(entry, BrokenPackage):
                broken.append(entry)
                continue
            where = (distribution_label(entry.dist), entry_point_label(entry))
            try:
                plugin = entry.load()
                if manager.is_registered(plugin):  # one module behind two entry points
                    continue
                name = manager.register(plugin, name=entry.value)
            except Exception as exc:
                if isinstance(exc, pluggy.PluginValidationError):
                    exc = _refused(exc)
                broken.append(BrokenPackage(*where, first_line(exc)))
                continue
            if name is not None:
                installed[name] = where
                origins[name] = PluginOrigin.of(entry)
                if distribution_name(entry.dist) == hookspecs.PROJECT:
                    builtins.add(name)
    _register_given(manager, plugins)
    while True:  # a misspelled hook is an error, not a silent no-op: the package is broken
        try:
            manager.check_pending()
            break
        except pluggy.PluginValidationError as exc:
            name = manager.get_name(exc.plugin)
            if name not in installed:
                raise _refused(exc) from None
            manager.unregister(exc.plugin)
            broken.append(BrokenPackage(*installed.pop(name), first_line(_refused(exc))))
    registry = PluginRegistry()
    broken += _run_hooks(manager, registry, installed, builtins, origins)
    registry._broken = tuple(broken)
    for package in broken:
        warnings.warn(
            f"plug-in package {package.distribution} failed to load and is skipped "
            f"(entry point {package.entry_point}): {package.error}",
            PluginLoadWarning,
            stacklevel=2,
        )
    return registry


def _register_given(manager: pluggy.PluginManager, plugins: Iterable[object]) -> None:
    """Register the plug-ins handed to load_registry; any problem raises PluginError."""
    try:
        given = list(plugins)
    except TypeError:
        raise PluginError(
            f"plugins must be an iterable of modules or objects, got {plugins!r}"
        ) from None
    for plugin in given:
        try:
            manager.register(plugin)
        except pluggy.PluginValidationError as exc:
            raise _refused(exc) from None
        except ValueError as exc:  # registered twice, or a name taken
            raise PluginError(f"plug-in {plugin!r} cannot be registered: {exc}") from None


def _run_hooks(
    manager: pluggy.PluginManager,
    registry: PluginRegistry,
    installed: dict[str, tuple[str, str]],
    builtins: set[str],
    origins: dict[str, PluginOrigin],
) -> list[BrokenPackage]:
    """Each package's hook, one package at a time and all or nothing; the installed
    packages that failed (the others raise PluginError)."""
    arguments = {"registry": registry}
    broken = []
    # The built-ins first, so that a package clashing with them (a name, a flag, a plate
    # constant declared otherwise) is the one skipped, never the built-ins; then pluggy's
    # own calling order (the last registered first). One implementation at a time, with
    # its arguments as pluggy passes them (a subset of the hook's, by name).
    impls = reversed(manager.hook.plateimpact_register.get_hookimpls())
    for impl in sorted(impls, key=lambda impl: impl.plugin_name not in builtins):
        attempted: list[tuple[str, str]] = []
        try:
            with registry._all_or_nothing(attempted):
                impl.function(*[arguments[name] for name in impl.argnames])
        except Exception as exc:
            where = installed.get(impl.plugin_name)
            if where is not None:
                broken.append(BrokenPackage(*where, first_line(exc), tuple(attempted)))
            elif isinstance(exc, PlateImpactError):
                raise
            else:
                raise PluginError(
                    f"the plateimpact_register hook of {impl.plugin_name} failed: {first_line(exc)}"
                ) from exc
            continue
        origin = origins.get(impl.plugin_name)
        if origin is not None:
            for kind, name in attempted:  # the latest load wins: what is installed now
                _ORIGINS[registry.get(kind, name)] = origin
    return broken


@functools.cache
def default_registry() -> PluginRegistry:
    """The registry of every installed plug-in package, loaded on first request."""
    return load_registry()
