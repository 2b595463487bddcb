"""A model variant: plug-in names and settings, as a study and its archive record them."""

from __future__ import annotations

import json
from collections.abc import Mapping
from typing import Any

import attrs
import numpy as np

from ..base.errors import ParameterError
from ..base.parameters import Parameter
from ..base.untrusted import load_json
from ..model.impact import REST_SPEED_FRACTION
from ..registry.plugin_registry import KINDS, PluginRegistry, default_registry
from .simulation import Simulation


class _NotJson(Exception):
    """A setting value with no JSON form of its own (a plug-in's table, ...)."""


def _json_value(value: object) -> object:
    """numpy values as JSON values; anything else is for its declaration to convert."""
    if isinstance(value, np.generic):
        return value.item()
    if isinstance(value, np.ndarray):
        return value.tolist()
    raise _NotJson


def _as_json(settings: Mapping[str, Any]) -> dict[str, Any] | None:
    """``settings`` as JSON values, or None if one has no JSON form of its own."""
    try:
        found: dict[str, Any] = json.loads(
            json.dumps(dict(settings), default=_json_value, sort_keys=True)
        )
    except _NotJson:
        return None
    return found


def _settings(value: Mapping[str, Any] | None) -> dict[str, Any]:
    """A settings mapping checked; its values as JSON where they are plain values (the
    others are converted by their declarations once the plug-in is known)."""
    if value is not None and not isinstance(value, Mapping):
        raise ParameterError(
            "settings", f"settings must be a mapping of names to values, got {value!r:.80}"
        )
    if not all(isinstance(name, str) for name in value or {}):
        raise ParameterError("settings", f"setting names must be strings, got {list(value or {})}")
    return _as_json(value or {}) or dict(value or {})


def _declared_json(declared: Mapping[str, Parameter], settings: dict[str, Any]) -> dict[str, Any]:
    """Settings whose values are not all JSON, converted by the plug-in's declarations
    ``declared`` (``Parameter.to_json``: a table setting gives its rows), so that a variant
    holds what the archive stores."""
    converted = {
        name: declared[name].json_value(value) if name in declared else value
        for name, value in settings.items()
    }
    found = _as_json(converted)
    if found is None:
        bad = next(v for v in converted.values() if _as_json({"v": v}) is None)
        raise ParameterError("settings", f"setting value {bad!r:.80} is not a JSON value")
    return found


def check_name(instance: object, attribute: attrs.Attribute, value: object) -> None:
    """A study or run name, which names an archive group: non-empty, printable (no NUL,
    which HDF5 would cut the name at), no '/', no surrounding space."""
    name = value if isinstance(value, str) else ""
    if not name or name != name.strip() or "/" in name or not name.isprintable():
        raise ParameterError(
            attribute.name,
            f"{attribute.name} must be a printable name without '/' or surrounding space, "
            f"got {value!r}",
        )


def check_plugin_name(instance: object, attribute: attrs.Attribute, value: object) -> None:
    """A plug-in name: a string (which plug-in it names is checked when it is run)."""
    if not isinstance(value, str):
        raise ParameterError(
            attribute.name, f"{attribute.name} must be a plug-in name, got {value!r:.60}"
        )


@attrs.frozen
class Variant:
    """One model variant of a study: plug-in names and their settings [SI].

    Settings are held as JSON values, exactly as the archive stores them, so a variant
    read back from an archive equals this one: a value with no JSON form of its own (a
    plug-in's table) is converted by the setting's declaration (``Parameter.to_json``).
    A plug-in not named is the installed packages' default of its kind (the registry's
    ``default``); the plug-ins are looked up there, too, to convert such a value.
    """

    name: str = attrs.field(validator=check_name)
    resistance: str = attrs.field(
        factory=lambda: default_registry().default("resistance"), validator=check_plugin_name
    )
    failure: str = attrs.field(
        factory=lambda: default_registry().default("failure"), validator=check_plugin_name
    )
    integrator: str = attrs.field(
        factory=lambda: default_registry().default("integrator"), validator=check_plugin_name
    )
    resistance_settings: dict[str, Any] = attrs.field(factory=dict, converter=_settings)
    failure_settings: dict[str, Any] = attrs.field(factory=dict, converter=_settings)
    integrator_settings: dict[str, Any] = attrs.field(factory=dict, converter=_settings)
    rest_speed_fraction: float = REST_SPEED_FRACTION.field()

    def __attrs_post_init__(self) -> None:
        for kind in KINDS:
            settings = getattr(self, f"{kind}_settings")
            if _as_json(settings) is None:  # the installed plug-in's declarations convert it
                cls = default_registry().get(kind, getattr(self, kind))
                converted = _declared_json(cls.setting_declarations(), settings)
                object.__setattr__(self, f"{kind}_settings", converted)

    def simulation(self, registry: PluginRegistry | None = None) -> Simulation:
        """The resolved model and integrator (plug-ins looked up by name once)."""
        return Simulation.from_names(
            self.resistance,
            self.failure,
            self.integrator,
            resistance_settings=self.resistance_settings,
            failure_settings=self.failure_settings,
            integrator_settings=self.integrator_settings,
            rest_speed_fraction=self.rest_speed_fraction,
            registry=registry,
        )

    def to_json(self) -> str:
        """The variant as JSON text: every field, keys sorted (:meth:`from_json` reads it)."""
        return json.dumps(attrs.asdict(self), sort_keys=True)

    @classmethod
    def from_json(cls, text: str) -> Variant:
        """The variant of :meth:`to_json`'s text (an archive's record, which may come from
        anyone): malformed or too deeply nested JSON, a key given twice, an unknown key
        or a value of the wrong type is a one-line ParameterError."""
        data = load_json(text, "variant", _variant_error)
        if not isinstance(data, dict):
            raise ParameterError("variant", f"variant: expected a JSON object, got {data!r:.60}")
        known = {field.name for field in attrs.fields(cls)}
        unknown = sorted(set(data) - known)
        if unknown:
            raise ParameterError(
                "variant",
                f"variant: unknown key {unknown[0]!r:.60} (known: {', '.join(sorted(known))})",
            )
        return cls(**data)


def _variant_error(message: str) -> ParameterError:
    return ParameterError("variant", message)
