"""``plateimpact.presets``: the preset plates and the default sphere of the installed
plug-in packages (they register them; the core knows none).

>>> from plateimpact import presets
>>> presets.plate(name)          # a preset plate by name (UnknownNameError lists them)
>>> presets.PLATES               # every preset, by name
>>> presets.DEFAULT_SPHERE       # the sphere used unless one is given
>>> presets.SPHERE_DENSITY       # its density [kg/m³], which a sphere of another radius keeps

Read from :func:`~plateimpact.default_registry` (the installed packages) on first use;
code that holds a registry reads ``registry.plate(name)``, ``registry.plates`` and
``registry.sphere`` instead.
"""

from __future__ import annotations

from typing import Any

from ..model.bodies import Plate
from .plugin_registry import default_registry


def plate(name: str) -> Plate:
    """The preset plate ``name``; UnknownNameError lists the choices."""
    return default_registry().plate(name)


def __getattr__(name: str) -> Any:
    if name == "PLATES":
        return default_registry().plates
    if name == "DEFAULT_SPHERE":
        return default_registry().sphere
    if name == "SPHERE_DENSITY":
        return default_registry().sphere_density
    raise AttributeError(f"module {__name__!r} has no attribute {name!r}")
