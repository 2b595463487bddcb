"""The one hook of plateimpact: a plug-in package registers its classes.

A plug-in package exposes, in the module named by its ``plateimpact`` entry point::

    from plateimpact import hookimpl

    @hookimpl
    def plateimpact_register(registry):
        registry.add(MyResistanceLaw)

and declares in its ``pyproject.toml``::

    [project.entry-points.plateimpact]
    myplugin = "my_package"

The hook runs once, when the registry is loaded; no hook is ever called while scenes are
being integrated. Real work is done by the registered classes' methods.
"""

from __future__ import annotations

from typing import Protocol

import pluggy

PROJECT = "plateimpact"
hookspec = pluggy.HookspecMarker(PROJECT)
hookimpl = pluggy.HookimplMarker(PROJECT)


class Registrar(Protocol):
    """What the hook is given: something that takes plug-in classes
    (:class:`plateimpact.PluginRegistry`)."""

    def add(self, cls: type) -> None: ...


@hookspec
def plateimpact_register(registry: Registrar) -> None:
    """Add this package's ResistanceLaw, FailureModel and Integrator classes to ``registry``."""
