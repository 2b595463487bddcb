"""Shattering: a brittle plate that breaks up at P* and keeps part of its resistance."""

from typing import final

import attrs
import numpy as np

from plateimpact import Contact, FailureModel, Parameter, Range, SceneBatch
from plateimpact_plugins.report import CRITICAL_PENETRATION

RESIDUAL_RESISTANCE = Parameter(
    "residual_resistance",
    "fraction r of the intact plate's resistance that its fragments keep once it shatters",
    range=Range(0.0, 1.0),
    default=0.0,
)


@final
@attrs.frozen
class Brittle(FailureModel):
    """A brittle plate shatters when P reaches P* [m]; its fragments then resist with the
    fraction r of the intact force, r F* [N], until the whole sphere has passed the back
    face: its shallowest point, P − 2 Rs deep, below the thickness T [m]."""

    name = "brittle"
    plate_constants = (CRITICAL_PENETRATION,)

    residual_resistance: float = RESIDUAL_RESISTANCE.field()

    def onset_penetration(self, scenes: SceneBatch) -> np.ndarray:
        return scenes.critical_penetration

    def force_change(self, contact: Contact) -> tuple[np.ndarray, np.ndarray]:
        drag, lift = contact.law.contact_force(
            contact.penetration, contact.obliquity, contact.speed
        )
        lost = 1.0 - self.residual_resistance
        return -lost * drag, -lost * lift

    def perforation_margin(self, contact: Contact) -> np.ndarray:
        scenes = contact.scenes
        return contact.penetration - 2.0 * scenes.radius - scenes.thickness
