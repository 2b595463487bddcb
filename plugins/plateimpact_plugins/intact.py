"""A plate that never fails."""

from __future__ import annotations

from typing import final

import attrs
import numpy as np

from plateimpact import Contact, FailureKernels, FailureModel, KernelContact, SceneBatch


def no_force_change(contact: KernelContact) -> tuple[float, float]:
    """An intact plate's force is the intact force: no change [N]."""
    return 0.0, 0.0


def never_perforated(contact: KernelContact) -> float:
    """An intact plate is never perforated: −inf [m]."""
    return -np.inf


#: The functions of numbers a compiled path compiles.
KERNELS = (no_force_change, never_perforated)


@final
@attrs.frozen
class Intact(FailureModel):
    """The plate never fails, whatever P* says: the sphere ricochets or embeds.

    The report's force law has no back surface, so an intact plate behaves as a
    half-space; this is the report's "extremely large P*" limit. It adds neither failure
    event, so the driver evaluates neither margin; its methods say the same thing on
    their own (onset never, no change, never perforated).
    """

    name = "intact"
    events = ()
    kernels = FailureKernels(no_force_change, never_perforated)

    def onset_penetration(self, scenes: SceneBatch) -> np.ndarray:
        return np.full(scenes.size, np.inf)

    def force_change(self, contact: Contact) -> tuple[np.ndarray, np.ndarray]:
        nothing = np.zeros(contact.penetration.shape)
        return nothing, nothing.copy()

    def perforation_margin(self, contact: Contact) -> np.ndarray:
        return np.full(contact.penetration.shape, -np.inf)
