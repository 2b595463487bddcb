"""The options every simulating command shares, derived from the declarations.

Plate and sphere options come from the core's parameters (``--thickness``,
``--radius``, ``--mass``) and from the plate constants the installed plug-ins declare
(``--a``, ``--pstar``, ...); model options are the plug-in names and ``--set
SLOT.NAME=VALUE`` for any setting or plate constant, with the flags a plug-in's settings
declare (``--rtol``, ``--step``, ``--pstar-table``) as aliases. Help text, units, ranges
and the flag an error names all come from the same declarations.
"""

from __future__ import annotations

import argparse
from collections.abc import Iterable
from typing import Any

import attrs

from ..base.errors import UnknownNameError
from ..base.parameters import Parameter, json_literal
from ..base.untrusted import load_json
from ..model.bodies import MASS, RADIUS, THICKNESS, Plate, Sphere
from ..model.impact import REST_SPEED_FRACTION, ImpactModel
from ..model.scene import IMPACT_OBLIQUITY, IMPACT_SPEED
from ..registry.plugin_registry import KINDS, PluginRegistry
from ..run.simulation import Simulation
from ..storage.plate_file import load_plate_file
from .common import UsageError

#: The model slots ``--set`` knows besides the plug-in kinds.
SET_SLOTS = (*KINDS, "model", "plate")
#: Which flag named which parameter, for error messages: set while arguments are read.
TYPED_FLAGS = "_typed_flags"


def _dest(flag: str) -> str:
    return flag.lstrip("-").replace("-", "_")


def metavar(declared: Parameter) -> str:
    """What a flag's value is called in help: its unit, or its name if it has none."""
    unit = declared.user_unit
    if unit == "1":
        return declared.name.upper()
    return unit.upper().replace("/", "_").replace("^", "")


def _aliases(registry: PluginRegistry) -> dict[str, tuple[str, str, list[tuple[str, Parameter]]]]:
    """Setting flags declared by plug-ins: flag -> (kind, setting, [(plug-in, declaration)])."""
    found: dict[str, tuple[str, str, list[tuple[str, Parameter]]]] = {}
    for kind in KINDS:
        for name in registry.names(kind):
            for setting, declared in registry.get(kind, name).setting_declarations().items():
                if declared.flag:
                    entry = found.setdefault(declared.flag, (kind, setting, []))
                    entry[2].append((name, declared))
    return found


def add_model_options(parser: argparse.ArgumentParser, registry: PluginRegistry) -> None:
    """--resistance, --failure, --integrator, --set and the declared setting aliases."""
    group = parser.add_argument_group(
        "model (plug-ins by name; see 'plateimpact plugins --details')"
    )
    for kind in KINDS:  # the plug-in of each kind when none is named: the registry's
        default = registry.defaults.get(kind, "none")
        choices = ", ".join(registry.names(kind))
        # No argparse default: a command can tell a name typed from none (run --inputs).
        group.add_argument(f"--{kind}", help=f"{kind}: {choices} (default {default})")
    group.add_argument(
        "--set",
        action="append",
        default=[],
        metavar="SLOT.NAME=VALUE",
        help=f"a setting or plate constant, in the units 'plugins --details' lists; SLOT is "
        f"one of {', '.join(SET_SLOTS)} (e.g. --set integrator.rtol=1e-9); repeatable",
    )
    for flag, (kind, setting, declarers) in sorted(_aliases(registry).items()):
        owners = "; ".join(f"{name}: default {d.format(d.default)}" for name, d in declarers)
        declared = declarers[0][1]
        help_text = f"--set {kind}.{setting}=: {declared.description} ({owners})"
        group.add_argument(flag, dest=_dest(flag), metavar=metavar(declared), help=help_text)


def add_body_options(
    parser: argparse.ArgumentParser, registry: PluginRegistry, *, many_presets: bool = False
) -> None:
    """--preset (repeatable if ``many_presets``), --plate-file, --thickness, every declared
    plate constant, --radius, --mass."""
    group = parser.add_argument_group("plate and sphere (override the preset)")
    group.add_argument(
        "--preset",
        action="append" if many_presets else "store",
        help=f"plate preset: {', '.join(registry.plates)}"
        + ("; repeatable" if many_presets else ""),
    )
    group.add_argument(
        "--plate-file",
        metavar="FILE",
        help="plate from a plate file (JSON, e.g. written by 'plateimpact calibrate --out'); "
        "not with --preset or the plate options",
    )
    for declared in (THICKNESS, *_constant_flags(registry).values()):
        assert declared.flag is not None
        group.add_argument(
            declared.flag,
            dest=_dest(declared.flag or ""),
            metavar=metavar(declared),
            help=declared.help(),
        )
    try:
        sphere: Sphere | None = registry.sphere
    except UnknownNameError:  # no package declares one: the sphere must be given
        sphere = None
    for declared, value in ((RADIUS, "radius"), (MASS, "mass")):
        default = "none" if sphere is None else declared.format(getattr(sphere, value))
        help_text = f"{declared.help()} (default {default})"
        group.add_argument(declared.flag or "", metavar=metavar(declared), help=help_text)


def _constant_flags(registry: PluginRegistry) -> dict[str, Parameter]:
    """The registered plate constants that declare a flag, by name."""
    return {name: p for name, p in registry.plate_constants.items() if p.flag}


def _by_name_or_short(declarations: Iterable[Parameter]) -> dict[str, Parameter]:
    """Plate constants by name, and by the short name of their file key (``c``)."""
    found = {p.short: p for p in declarations if p.short}
    found.update({p.name: p for p in declarations})
    return found


def typed(args: argparse.Namespace) -> dict[str, str]:
    """Parameter name -> the flag the user typed for it (for error messages)."""
    flags: dict[str, str] = getattr(args, TYPED_FLAGS, {})
    setattr(args, TYPED_FLAGS, flags)
    return flags


def _parse(declared: Parameter, text: str, flag: str, args: argparse.Namespace) -> Any:
    typed(args)[declared.name] = flag
    if declared.convert is json_literal:  # an undeclared setting: JSON, or else text
        return _literal(text, flag)  # (its declaration checks nothing more)
    return declared.parse(text)


def _literal(text: str, flag: str) -> Any:
    """The value of ``--set SLOT.NAME=TEXT`` for an undeclared setting: JSON read within
    untrusted.load_json's bounds (one line naming the flag), or the text itself when it
    is no JSON at all (``RK23``)."""
    return load_json(text, flag, UsageError, text_if_not_json=True)


class ModelChoice:
    """What the model options ask for: settings per slot and plate overrides [SI]."""

    def __init__(self, args: argparse.Namespace, registry: PluginRegistry) -> None:
        self.registry = registry
        typed_names = {kind: getattr(args, kind, None) for kind in KINDS}
        self.names = {
            kind: registry.default(kind) if name is None else name
            for kind, name in typed_names.items()
        }
        self.settings: dict[str, dict[str, Any]] = {kind: {} for kind in KINDS}
        self.model: dict[str, Any] = {}
        self.plate: dict[str, float] = {}
        self.plate_flags: dict[str, str] = {}
        for flag, (kind, setting, _) in _aliases(registry).items():
            value = getattr(args, _dest(flag), None)
            if value is not None:
                self._set(kind, setting, value, flag, args)
        for item in args.set:
            target, equals, value = item.partition("=")
            slot, dot, name = target.strip().partition(".")
            if not (equals and dot and name and slot in SET_SLOTS):
                raise UsageError(
                    f"--set: expected SLOT.NAME=VALUE with SLOT one of {', '.join(SET_SLOTS)}, "
                    f"got {item!r}"
                )
            self._set(slot, name.strip(), value, f"--set {slot}.{name.strip()}", args)

    def _set(self, slot: str, name: str, text: str, flag: str, args: argparse.Namespace) -> None:
        if slot == "model":
            if name != REST_SPEED_FRACTION.name:
                raise UsageError(f"{flag}: the model's only setting is {REST_SPEED_FRACTION.name}")
            self.model[name] = _parse(REST_SPEED_FRACTION, text, flag, args)
            return
        if slot == "plate":
            known_constants = _by_name_or_short(self.registry.plate_constants.values())
            declared = THICKNESS if name == "thickness" else known_constants.get(name)
            if declared is None:
                known = ", ".join(["thickness", *self.registry.plate_constants])
                raise UsageError(f"{flag}: no plate constant {name!r}; plate constants: {known}")
            self.plate[declared.name] = _parse(declared, text, flag, args)
            self.plate_flags[declared.name] = flag
            return
        cls = self.registry.get(slot, self.names[slot])
        settings = cls.setting_declarations()
        constants = _by_name_or_short(cls.plate_constants)
        if name in constants and name not in settings:
            declared = constants[name]
            self.plate[declared.name] = _parse(declared, text, flag, args)
            self.plate_flags[declared.name] = flag
        elif name in settings:
            self.settings[slot][name] = _parse(settings[name], text, flag, args)
        else:
            known = ", ".join(sorted([*settings, *constants])) or "none"
            raise UsageError(
                f"{flag}: {slot} {self.names[slot]!r} has no setting {name!r}; settings: {known}"
            )

    def simulation(self) -> Simulation:
        """The model and integrator asked for."""
        return Simulation.from_names(
            self.names["resistance"],
            self.names["failure"],
            self.names["integrator"],
            resistance_settings=self.settings["resistance"],
            failure_settings=self.settings["failure"],
            integrator_settings=self.settings["integrator"],
            registry=self.registry,
            **self.model,
        )


def model_choice(args: argparse.Namespace, registry: PluginRegistry) -> ModelChoice:
    """What the model options of ``args`` ask for, of the plug-ins of ``registry``."""
    return ModelChoice(args, registry)


def sphere_of(args: argparse.Namespace, registry: PluginRegistry) -> Sphere:
    """The default sphere, or the one of --radius [mm] and --mass [g]."""
    if args.radius is not None and args.mass is not None:
        radius = _parse(RADIUS, args.radius, "--radius", args)
        return Sphere(radius=radius, mass=_parse(MASS, args.mass, "--mass", args))
    sphere = registry.sphere
    if args.radius is None and args.mass is None:
        return sphere
    radius = sphere.radius if args.radius is None else _parse(RADIUS, args.radius, "--radius", args)
    if args.mass is not None:
        return Sphere(radius=radius, mass=_parse(MASS, args.mass, "--mass", args))
    return Sphere.of_density(radius, registry.sphere_density)  # a new radius keeps the density


def bodies(
    args: argparse.Namespace, choice: ModelChoice, model: ImpactModel
) -> tuple[Sphere, Plate, str]:
    """Sphere, plate and its label from --preset / --plate-file / plate options and --set."""
    overrides = dict(choice.plate)
    flags = dict(choice.plate_flags)
    for declared in (THICKNESS, *_constant_flags(choice.registry).values()):
        text = getattr(args, _dest(declared.flag or ""), None)
        if text is not None:
            overrides[declared.name] = _parse(declared, text, declared.flag or "", args)
            flags[declared.name] = declared.flag or ""
    needed = model.plate_constants()
    for name, flag in flags.items():
        if name != "thickness" and name not in needed:
            uses = ", ".join(needed) or "no plate constant"
            raise UsageError(
                f"{flag}: the model ({model.resistance.name} + {model.failure.name}) does not use "
                f"{name}; it reads {uses}"
            )
    if args.plate_file is not None:
        given = ["--preset"] * (args.preset is not None) + sorted(flags.values())
        if given:
            raise UsageError(f"--plate-file cannot be combined with {', '.join(given)}")
        base, label = load_plate_file(args.plate_file, choice.registry), args.plate_file
    elif args.preset is not None:
        base, label = choice.registry.plate(args.preset), args.preset
    else:
        required = [THICKNESS, *(p for p in needed.values() if not p.has_default)]
        missing = [p.flag or f"--set plate.{p.name}" for p in required if p.name not in overrides]
        if missing:
            raise UsageError(
                "--preset is required unless the plate options the model needs are given "
                f"(missing {', '.join(missing)})"
            )
        thickness = overrides.pop("thickness")
        return sphere_of(args, choice.registry), Plate("custom", thickness, overrides), "custom"
    if "thickness" in overrides:
        _check_new_thickness(base, label, overrides, flags, needed)
        base = attrs.evolve(base, thickness=overrides.pop("thickness"))
    if flags:
        base = Plate(base.material, base.thickness, {**base.constant_values(), **overrides})
        label = f"{label}+custom"
    return sphere_of(args, choice.registry), base, label


def _check_new_thickness(
    preset: Plate,
    label: str,
    overrides: dict[str, float],
    flags: dict[str, str],
    needed: dict[str, Parameter],
) -> None:
    """Refuse a preset's plate at another thickness without its constants: the model has
    no back surface, T enters only through a, b, P*, ... fitted at the preset's T
    (docs/model.md, "The plate thickness"), so a new T alone would change nothing."""
    thickness = overrides["thickness"]
    missing = [
        p.flag or f"--set plate.{p.name}"
        for p in needed.values()
        if not p.has_default and p.name not in overrides
    ]
    if thickness == preset.thickness or not missing:
        return
    raise UsageError(
        f"{flags['thickness']}: the model uses T only to bound craters; a thickness acts "
        f"through the plate constants, and {label}'s were fitted at "
        f"{THICKNESS.format(preset.thickness)} mm: give {', '.join(missing)} for "
        f"{THICKNESS.format(thickness)} mm too, or fit them with 'plateimpact calibrate'"
    )


def scene_flags(args: argparse.Namespace, speed_flag: str, obliquity_flag: str) -> None:
    """Name the flags that carried the impact speed and obliquity."""
    typed(args).update({IMPACT_SPEED.name: speed_flag, IMPACT_OBLIQUITY.name: obliquity_flag})


def flag_of(
    args: argparse.Namespace, parameter: str, registry: PluginRegistry | None
) -> str | None:
    """The flag that set ``parameter``: as typed, or the one its declaration names (a
    core quantity's, or a plate constant's of ``registry``)."""
    if parameter in typed(args):
        return typed(args)[parameter]
    constants = {} if registry is None else registry.plate_constants
    declared = {p.name: p for p in (THICKNESS, RADIUS, MASS)} | constants
    if parameter in declared:
        return declared[parameter].flag
    return None
