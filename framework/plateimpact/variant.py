"""A model variant: plug-in names and settings, as a study and its archive record them."""

from __future__ import annotations

import json
from collections.abc import Mapping
from typing import Any

import attrs
import numpy as np

from .errors import ParameterError
from .model import REST_SPEED_FRACTION
from .registry import PluginRegistry
from .simulation import DEFAULT_FAILURE, DEFAULT_INTEGRATOR, DEFAULT_RESISTANCE, Simulation


def _json_value(value: object) -> object:
    """Settings as JSON values, so that a variant is archived and read back unchanged."""
    if isinstance(value, np.generic):
        return value.item()
    if isinstance(value, np.ndarray):
        return value.tolist()
    if hasattr(value, "as_setting"):  # e.g. a PstarTable: its rows
        return value.as_setting()
    raise ParameterError("settings", f"setting value {value!r} is not a JSON value")


def _settings(value: dict[str, Any] | None) -> dict[str, Any]:
    if not isinstance(value, Mapping | None):
        raise ParameterError("settings", f"settings must be a mapping, got {value!r}")
    settings: dict[str, Any] = json.loads(
        json.dumps(dict(value or {}), default=_json_value, sort_keys=True)
    )
    return settings


def check_name(instance: object, attribute: attrs.Attribute, value: object) -> None:
    """A study or run name: non-empty, no '/', no surrounding space."""
    if not isinstance(value, str) or not value or "/" in value or value != value.strip():
        raise ParameterError(
            attribute.name, f"{attribute.name} must be a non-empty name without '/', got {value!r}"
        )


@attrs.frozen
class Variant:
    """One model variant of a study: plug-in names and their settings [SI].

    Settings are held as JSON values (a :class:`PstarTable` becomes its rows), exactly as
    the archive stores them, so a variant read back from an archive equals this one.
    """

    name: str = attrs.field(validator=check_name)
    resistance: str = DEFAULT_RESISTANCE
    failure: str = DEFAULT_FAILURE
    integrator: str = DEFAULT_INTEGRATOR
    resistance_settings: dict[str, Any] = attrs.field(factory=dict, converter=_settings)
    failure_settings: dict[str, Any] = attrs.field(factory=dict, converter=_settings)
    integrator_settings: dict[str, Any] = attrs.field(factory=dict, converter=_settings)
    rest_speed_fraction: float = REST_SPEED_FRACTION.field()

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
        return json.dumps(attrs.asdict(self), sort_keys=True)

    @classmethod
    def from_json(cls, text: str) -> Variant:
        return cls(**json.loads(text))
