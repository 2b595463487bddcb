"""Plate files: one plate as JSON, in user units, for ``--plate-file`` and study scripts.

    {"format": "plateimpact-plate-1", "material": "2024-T3", "thickness_mm": 3.18,
     "a_N_m2": 1.01e9, "b_kg_m3": 1260.0, "pstar_mm": 3.0, "alpha_deg": 45.0,
     "units": {...}, "calibration": {...}}

Besides ``material`` and ``thickness_mm``, every key is a plate constant, named as its
declaring plug-in's :attr:`Parameter.key <plateimpact.Parameter.key>` (the unit in the
name), so a third-party constant ``c`` is simply ``"c": 0.003``. The keys are those of
``plateimpact presets --json``; ``units`` spells each out; ``calibration`` and ``notes``
are kept for the reader. Any other key is an error: a misspelled constant is never
silently ignored.
"""

from __future__ import annotations

import json
import os
from collections.abc import Mapping
from typing import Any

from ..base.errors import ParameterError, PlateFileError, PluginError
from ..base.parameters import Parameter
from ..base.untrusted import described, load_json_file, printable
from ..model.bodies import THICKNESS, Plate
from ..registry.plugin_registry import PluginRegistry, default_registry
from .output import write_text

FORMAT = "plateimpact-plate-1"
#: Keys that are not constants.
RESERVED = ("format", "material", "units", "calibration", "notes")


def _declarations(registry: PluginRegistry) -> dict[str, Parameter]:
    """Thickness and every plate constant ``registry`` declares, by file key."""
    if not isinstance(registry, PluginRegistry):
        raise PluginError(f"registry must be a PluginRegistry, got {registry!r:.80}")
    declared = [THICKNESS, *registry.plate_constants.values()]
    return {p.key: p for p in declared}


def plate_to_dict(
    plate: Plate, extra: Mapping[str, Any] | None = None, *, registry: PluginRegistry
) -> dict[str, Any]:
    """The plate-file object of ``plate``, its constants' keys and units as ``registry``
    declares them; ``extra`` adds keys (e.g. ``calibration``)."""
    by_name = {p.name: p for p in _declarations(registry).values()}
    out: dict[str, Any] = {"format": FORMAT, "material": plate.material}
    units: dict[str, str] = {}
    for name, value in [("thickness", plate.thickness), *plate.constants]:
        declared = by_name.get(name)
        if declared is None:
            raise PlateFileError(f"plate constant {name!r} is declared by no installed plug-in")
        # Exact: reading the file gives back the same bits (45, not 45.00000000000001).
        exact = declared.user_number(value)
        out[declared.key] = value / declared.scale if exact is None else exact
        units[declared.key] = f"{declared.description} [{declared.user_unit}]"
    out["units"] = units
    out.update(extra or {})
    return out


def plate_from_dict(data: object, source: str = "plate file", *, registry: PluginRegistry) -> Plate:
    """A :class:`Plate` from a plate-file object; :class:`PlateFileError` names ``source``
    and the key."""
    if not isinstance(data, dict):
        raise PlateFileError(f"{source}: expected a JSON object, got {described(data)}")
    if data.get("format") != FORMAT:
        raise PlateFileError(
            f"{source}: not a plateimpact plate file (format {data.get('format')!r:.60}, "
            f"expected {FORMAT!r})"
        )
    declarations = _declarations(registry)
    missing = [key for key in ("material", THICKNESS.key) if key not in data]
    if missing:
        raise PlateFileError(
            f"{source}: missing key{'s' * (len(missing) > 1)} {', '.join(missing)}"
        )
    if not isinstance(data["material"], str):
        raise PlateFileError(
            f"{source}: material must be a string, got {described(data['material'])}"
        )
    values = {}
    for key, value in data.items():
        if key in RESERVED:
            continue
        declared = declarations.get(key)
        if declared is None:
            known = ", ".join(sorted(declarations))
            raise PlateFileError(f"{source}: unknown key {key!r:.60} (plate keys: {known})")
        if isinstance(value, bool) or not isinstance(value, int | float):
            raise PlateFileError(
                f"{source}: {key}: must be a number {declared.describe_range()}, got "
                f"{described(value)}"
            )
        values[declared.name] = value * declared.scale
        try:
            if declared is not THICKNESS:
                declared.check(values[declared.name])
        except ParameterError as exc:
            raise PlateFileError(f"{source}: {key}: {exc}") from None
    thickness = values.pop("thickness")
    try:
        return Plate(data["material"], thickness, values)
    except ParameterError as exc:
        key = next((k for k, p in declarations.items() if p.name == exc.parameter), exc.parameter)
        raise PlateFileError(f"{source}: {key}: {exc}") from None


def load_plate_file(path: str | os.PathLike[str], registry: PluginRegistry | None = None) -> Plate:
    """The plate in a plate file (JSON; see the module's description), its keys read as
    ``registry`` declares them (an entry point of the API: without one, the installed
    plug-ins, docs/plugins.md "Where the registry comes from")."""
    registry = default_registry() if registry is None else registry
    # bounded (nesting, integer digits, size), a duplicate key refused (never the last
    # silently winning); a BOM is allowed
    data = load_json_file(path, PlateFileError)
    return plate_from_dict(data, printable(os.fspath(path), 200), registry=registry)


def plate_file_text(
    plate: Plate, extra: Mapping[str, Any] | None = None, *, registry: PluginRegistry
) -> str:
    """The plate file of ``plate`` as text (pretty JSON; P* = inf is written ``Infinity``)."""
    return json.dumps(plate_to_dict(plate, extra, registry=registry), indent=2) + "\n"


def save_plate_file(
    path: str | os.PathLike[str],
    plate: Plate,
    extra: Mapping[str, Any] | None = None,
    registry: PluginRegistry | None = None,
) -> None:
    """Write ``plate`` to ``path`` as a plate file, atomically (storage.output); an entry
    point of the API: without ``registry``, the installed plug-ins declare its keys."""
    registry = default_registry() if registry is None else registry
    write_text(path, plate_file_text(plate, extra, registry=registry), "plate file", kind="json")
