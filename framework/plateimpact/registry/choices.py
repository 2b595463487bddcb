"""What plug-in packages name besides their classes: the plug-in of each kind used when
none is named, named plates (presets), the default sphere and procedures that commands
run (``calibration``: what ``plateimpact calibrate`` fits).

The core names none of them: a package declares them when it registers
(``registry.add(cls, default=True)``, ``registry.add_plate(name, plate)``,
``registry.set_sphere(sphere, density=..., material=...)``), and the command line,
:class:`Simulation` and ``plateimpact.presets`` read them from the registry. Two packages
may not claim the same default, preset name or sphere differently: the second is refused
in one line (and, as an installed package, skipped).
"""

from __future__ import annotations

import math
from collections.abc import Callable
from typing import Any

from ..base.errors import PluginError, UnknownNameError
from ..model.bodies import Plate, Sphere


class Choices:
    """Defaults, presets, the default sphere and procedures of a :class:`PluginRegistry`;
    for a default, the module that declared it (named when a second claim is refused)."""

    def __init__(self) -> None:
        self._defaults: dict[str, tuple[str, str]] = {}  # kind -> (name, module)
        self._plates: dict[str, Plate] = {}  # preset name -> plate
        self._sphere: tuple[Sphere, float, str] | None = None  # sphere, density, material
        self._procedures: dict[str, Callable[[], Any]] = {}  # name -> loader
        self._loaded: dict[str, Any] = {}

    def __getstate__(self) -> dict[str, Any]:
        # A registry travels with its simulation to a worker process: the procedures go as
        # their loaders, never as what was loaded (a module does not pickle).
        return {**self.__dict__, "_loaded": {}}

    def _save_choices(self) -> tuple[Any, ...]:
        return dict(self._defaults), dict(self._plates), self._sphere, dict(self._procedures)

    def _restore_choices(self, saved: tuple[Any, ...]) -> None:
        self._defaults, self._plates, self._sphere = dict(saved[0]), dict(saved[1]), saved[2]
        self._procedures = dict(saved[3])

    def _claim_default(self, kind: str, name: str, module: str) -> None:
        known = self._defaults.get(kind)
        if known is not None and known[0] != name:
            raise PluginError(
                f"default {kind} claimed twice: {known[0]!r} by {known[1]} and {name!r} by {module}"
            )
        self._defaults[kind] = (name, module)

    def default(self, kind: str) -> str:
        """The name of the ``kind`` plug-in used when none is named (``"resistance"``,
        ``"failure"``, ``"integrator"``); UnknownNameError if no package declared one."""
        known = self._defaults.get(kind)
        if known is None:
            raise UnknownNameError(
                f"no default {kind} is registered (no installed package declares one): "
                f"name the {kind} plug-in"
            )
        return known[0]

    @property
    def defaults(self) -> dict[str, str]:
        """The default plug-in name of each kind that has one."""
        return {kind: name for kind, (name, _) in self._defaults.items()}

    def add_plate(self, name: str, plate: Plate) -> None:
        """Register ``plate`` as the preset ``name`` (``--preset NAME``, ``presets``)."""
        if not (isinstance(name, str) and name and name == name.strip() and name.isprintable()):
            raise PluginError(f"a preset name must be printable text, got {name!r:.60}")
        if not isinstance(plate, Plate):
            raise PluginError(f"preset {name!r} must be a Plate, got {plate!r:.60}")
        known = self._plates.get(name)
        if known is not None and known != plate:
            raise PluginError(f"preset {name!r} is registered twice, as two different plates")
        self._plates[name] = plate

    @property
    def plates(self) -> dict[str, Plate]:
        """The preset plates by name, in the order registered."""
        return dict(self._plates)

    def plate(self, name: str) -> Plate:
        """The preset plate ``name``; UnknownNameError lists the choices."""
        known = self._plates.get(name) if isinstance(name, str) else None
        if known is None:
            choices = ", ".join(self._plates) or "none registered"
            raise UnknownNameError(f"unknown preset {name!r}; choose from: {choices}")
        return known

    def set_sphere(self, sphere: Sphere, *, density: float, material: str) -> None:
        """Declare the sphere used unless one is given, the density [kg/m³] that a sphere
        of another radius keeps (the command line's ``--radius``) and its material."""
        if not isinstance(sphere, Sphere):
            raise PluginError(f"the default sphere must be a Sphere, got {sphere!r:.60}")
        if not (isinstance(density, float | int) and math.isfinite(density) and density > 0):
            raise PluginError(f"the default sphere's density must be > 0 kg/m^3, got {density!r}")
        declared = (sphere, float(density), str(material))
        if self._sphere is not None and self._sphere != declared:
            raise PluginError("the default sphere is declared twice, as two different spheres")
        self._sphere = declared

    @property
    def sphere(self) -> Sphere:
        """The default sphere; UnknownNameError if no package declared one."""
        return self._declared_sphere()[0]

    @property
    def sphere_density(self) -> float:
        """The default sphere's material density [kg/m³]."""
        return self._declared_sphere()[1]

    @property
    def sphere_material(self) -> str:
        """The default sphere's material, a label (``"steel"``)."""
        return self._declared_sphere()[2]

    def _declared_sphere(self) -> tuple[Sphere, float, str]:
        if self._sphere is None:
            raise UnknownNameError(
                "no default sphere is registered (no installed package declares one): "
                "give the sphere (--radius and --mass)"
            )
        return self._sphere

    def add_procedure(self, name: str, load: Callable[[], Any]) -> None:
        """Register the procedure ``name`` (``"calibration"``): ``load()`` returns the object
        that provides it (a module), called on first use so that registering costs no
        import. PluginError if another package registered that name."""
        if not (isinstance(name, str) and name) or not callable(load):
            raise PluginError(f"a procedure needs a name and a loader, got {name!r:.60}")
        known = self._procedures.get(name)
        if known is not None and known is not load:
            raise PluginError(f"procedure {name!r} is registered twice")
        self._procedures[name] = load

    def procedure(self, name: str) -> Any:
        """The object providing the procedure ``name``; UnknownNameError if none does."""
        if name not in self._loaded:
            if name not in self._procedures:
                raise UnknownNameError(
                    f"no installed plug-in package provides the {name} procedure"
                )
            self._loaded[name] = self._procedures[name]()
        return self._loaded[name]
