"""Simulation: a model and an integrator chosen by plug-in names, resolved once."""

from __future__ import annotations

from collections.abc import Iterable, Mapping
from typing import Any

import attrs

from .batch import SceneBatch
from .integrator import Integrator
from .model import ImpactModel
from .registry import PluginRegistry, default_registry
from .results import BatchResult, Result
from .scene import Scene

DEFAULT_RESISTANCE = "poncelet"
DEFAULT_FAILURE = "plugging"
DEFAULT_INTEGRATOR = "dopri5"


@attrs.frozen
class Simulation:
    """Runs scenes through one resolved model and integrator.

    Build it from plug-in names with :meth:`from_names`, then call :meth:`run` for one
    scene or :meth:`run_batch` for many; the CLI does exactly this.
    """

    model: ImpactModel
    integrator: Integrator = attrs.field(validator=attrs.validators.instance_of(Integrator))

    @classmethod
    def from_names(
        cls,
        resistance: str = DEFAULT_RESISTANCE,
        failure: str = DEFAULT_FAILURE,
        integrator: str = DEFAULT_INTEGRATOR,
        *,
        resistance_settings: Mapping[str, Any] | None = None,
        failure_settings: Mapping[str, Any] | None = None,
        integrator_settings: Mapping[str, Any] | None = None,
        rest_speed_fraction: float = 1e-2,
        registry: PluginRegistry | None = None,
    ) -> Simulation:
        """Resolve each slot by name from ``registry`` (default: installed plug-ins)."""
        registry = registry or default_registry()
        model = ImpactModel(
            resistance=registry.create("resistance", resistance, **(resistance_settings or {})),
            failure=registry.create("failure", failure, **(failure_settings or {})),
            rest_speed_fraction=rest_speed_fraction,
        )
        return cls(model, registry.create("integrator", integrator, **(integrator_settings or {})))

    def run_batch(
        self, scenes: SceneBatch | Iterable[Scene], *, record_trajectory: bool = False
    ) -> BatchResult:
        """Results of many scenes, as arrays in the order given."""
        batch = scenes if isinstance(scenes, SceneBatch) else SceneBatch.from_scenes(scenes)
        return self.integrator.run(self.model, batch, record_trajectory=record_trajectory)

    def run(self, scene: Scene, *, record_trajectory: bool = False) -> Result:
        """The result of one scene."""
        return self.run_batch([scene], record_trajectory=record_trajectory).result(0)

    def describe(self) -> dict[str, object]:
        """Plug-in names, versions and settings."""
        return {
            **self.model.describe(),
            "integrator": self.integrator.name,
            "integrator_version": self.integrator.version,
            "integrator_settings": self.integrator.settings(),
        }


def run(scene: Scene, *, record_trajectory: bool = False, **names: Any) -> Result:
    """Run one scene; ``names`` are :meth:`Simulation.from_names` arguments."""
    return Simulation.from_names(**names).run(scene, record_trajectory=record_trajectory)
