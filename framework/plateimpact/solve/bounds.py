"""The error of scenes that exhausted a work bound, shared by the numpy and compiled paths."""

from __future__ import annotations

import numpy as np

from ..base.errors import IntegrationError
from .integrator import Integrator


def unfinished_error(
    integrator: Integrator, limit: str, setting: str, example: str, scene: np.ndarray, where: str
) -> IntegrationError:
    """The one-line error of a scene that exhausted a work bound: how far it got, and the
    setting to raise (on the command line too, where the integrator declares it)."""
    if setting in integrator.setting_declarations():
        change = f"raise {setting} (--set integrator.{setting}={example})"
    else:
        change = f"raise the integrator's {setting}"
    return IntegrationError(
        f"{integrator.name}: {scene.size} scene(s) unfinished after {limit} (first: scene "
        f"{int(scene[0])}, {where}); {change}"
    )
