"""A third-party plug-in package: Poncelet's law without the report's obliquity factor.

σ = a + b V² [N/m²], the classical form the report starts from ("F = A(a + bV²)"),
whatever the angle between the path and the force. It equals eq 1 at normal incidence.
"""

from __future__ import annotations

from typing import final

import attrs
import numpy as np

from plateimpact import PluginRegistry, ResistanceLaw, SceneBatch, hookimpl


@final
@attrs.frozen
class IsotropicPoncelet(ResistanceLaw):
    """σ = a + b V² [N/m²]."""

    name = "isotropic-poncelet"

    def stress(self, speed: np.ndarray, incidence: np.ndarray, batch: SceneBatch) -> np.ndarray:
        return batch.a + batch.b * speed * speed


@hookimpl
def plateimpact_register(registry: PluginRegistry) -> None:
    registry.add(IsotropicPoncelet)
