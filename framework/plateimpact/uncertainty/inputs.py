"""The inputs a distribution can be put on: the impact speed and obliquity, the sphere's
radius and mass, the plate's thickness, and every plate constant the installed plug-ins
declare (a, b, P*, α*, and a third party's), each named by its key with its user unit
(``speed_m_s``, ``pstar_mm``) and tied to the scene column it sets, with the declared range
that bounds its distribution."""

from __future__ import annotations

import attrs

from ..base.parameters import Parameter
from ..model.bodies import MASS, RADIUS, THICKNESS
from ..model.scene import IMPACT_OBLIQUITY, IMPACT_SPEED
from ..registry.plugin_registry import PluginRegistry


@attrs.frozen
class UncertainInput:
    """An input: its ``name`` in a spec, the scene ``column`` it sets [SI] and its
    declared ``parameter`` (unit, range; ``scale``: SI per user unit)."""

    name: str
    column: str
    parameter: Parameter

    @property
    def unit(self) -> str:
        """The user unit of its distribution's values."""
        return self.parameter.user_unit

    @property
    def user_range(self) -> tuple[float, float]:
        """The declared range [its user unit]."""
        declared = self.parameter.range
        return declared.low / self.parameter.scale, declared.high / self.parameter.scale

    def describe_range(self) -> str:
        """The declared range as a message says it (``in [0, 90) deg``)."""
        return self.parameter.range.describe(self.parameter.scale, self.unit)


def input_table(registry: PluginRegistry) -> dict[str, UncertainInput]:
    """Every input a distribution can be put on, by name."""
    core = {
        "speed_m_s": IMPACT_SPEED,
        "obliquity_deg": IMPACT_OBLIQUITY,
        "radius_mm": RADIUS,
        "mass_g": MASS,
        "thickness_mm": THICKNESS,
    }
    table = {name: UncertainInput(name, p.name, p) for name, p in core.items()}
    for column, declared in registry.plate_constants.items():
        table[declared.key] = UncertainInput(declared.key, column, declared)
    return table
