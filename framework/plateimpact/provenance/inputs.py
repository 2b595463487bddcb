"""The inputs record: everything a run reads, in user units, to run it again exactly.

    {"format": "plateimpact-inputs-1", "label": "2024-T3/3.18+custom",
     "impact_speed_m_s": 640.0, "impact_obliquity_deg": 60.0,
     "sphere": {"radius_mm": 3.175, "mass_g": 1.0497395506027971},
     "plate": {plate-file object: "thickness_mm", "a_N_m2", "pstar_mm", ...},
     "model": {"resistance": "poncelet", "resistance_version": "1.0",
               "resistance_settings": {}, "failure": ..., "integrator": "dopri5",
               "integrator_settings": {"rtol": 1e-08, ...}, "rest_speed_fraction": 0.01},
     "versions": {"python": ..., "plateimpact": ..., ...}, "source_commit": "...",
     "plugins": {"core": {...}, "resistance": {...}, ...}}  (provenance.code)

Every number is in the unit its key names (``_mm``, ``_g``, ``_deg``; a setting's key is
its declaration's :attr:`~plateimpact.Parameter.key`), written as the shortest number
that converts back to the same double (:meth:`~plateimpact.Parameter.user_number`), so
that :func:`read_run_inputs` rebuilds the run bit for bit. A value that no number in the
user's unit reaches (a mass computed from a density, now and then) is written in SI
under its SI key (``mass_kg``). ``versions``, ``source_commit`` and ``plugins`` are
provenance (provenance.metadata, provenance.code), not read back. The plate is
a plate file's object.
"""

from __future__ import annotations

import os
from collections.abc import Mapping
from typing import Any

import attrs

from ..base.errors import InputsError, ParameterError, PluginError, UnknownNameError
from ..base.parameters import Parameter
from ..base.untrusted import described, load_json_file, printable
from ..model.bodies import MASS, RADIUS, Sphere
from ..model.impact import REST_SPEED_FRACTION
from ..model.plugin import Plugin
from ..model.scene import IMPACT_OBLIQUITY, IMPACT_SPEED, Scene
from ..registry.plugin_registry import KINDS, PluginRegistry
from ..run.simulation import Simulation
from ..storage.plate_file import plate_from_dict

FORMAT = "plateimpact-inputs-1"
#: Keys of a record that are provenance or description, not read back (``csv_sha256``:
#: the trajectory a ``run --trajectory`` sidecar describes, cli.sidecar).
RECORD_ONLY = ("format", "label", "versions", "source_commit", "plugins", "csv_sha256")


def si_key(declared: Parameter) -> str:
    """The key of ``declared`` in its SI unit (``mass_kg``)."""
    return attrs.evolve(declared, display_unit=None, scale=1.0).key


def quantity(declared: Parameter, value: float) -> tuple[str, float]:
    """(key, number) of ``value`` [SI]: in the user's unit when a number there gives back
    exactly ``value``, else in SI under :func:`si_key`."""
    exact = declared.user_number(value)
    return (si_key(declared), float(value)) if exact is None else (declared.key, exact)


def sphere_record(sphere: Sphere) -> dict[str, float]:
    return dict(quantity(declared, getattr(sphere, declared.name)) for declared in (RADIUS, MASS))


def _settings_record(plugin: Plugin) -> dict[str, Any]:
    """A plug-in's settings by key, numbers in user units."""
    out: dict[str, Any] = {}
    values = plugin.settings()
    for name, declared in plugin.setting_declarations().items():
        value = values[name]
        number = isinstance(value, int | float) and not isinstance(value, bool)
        if number and declared.kind is float and declared.convert is None:
            key, value = quantity(declared, value)
        else:
            key = declared.key
        out[key] = value
    return out


def model_record(simulation: Simulation) -> dict[str, Any]:
    """Plug-in names, versions and every setting, numbers in user units."""
    model = simulation.model
    plugins = {"resistance": model.resistance, "failure": model.failure}
    plugins["integrator"] = simulation.integrator
    out: dict[str, Any] = {}
    for kind, plugin in plugins.items():
        out[kind] = plugin.name
        out[f"{kind}_version"] = plugin.version
        out[f"{kind}_settings"] = _settings_record(plugin)
    key, value = quantity(REST_SPEED_FRACTION, model.rest_speed_fraction)
    out[key] = value
    return out


# -- reading back: ``where`` is the prefix of a key in messages ("f.json: sphere.") --------


def _read_quantity(data: Mapping[str, Any], declared: Parameter, where: str) -> Any:
    """The SI value of ``declared`` in ``data``, from its user-unit or its SI key."""
    keys = list(dict.fromkeys((declared.key, si_key(declared))))
    given = [key for key in keys if key in data]
    if len(given) != 1:
        problem = f"give {' or '.join(keys)}, not both" if given else "missing"
        raise InputsError(f"{where}{declared.key}: {problem}")
    key = given[0]
    value = data[key]
    if value is None and declared.optional:
        return None
    if isinstance(value, bool) or not isinstance(value, int | float):
        raise InputsError(
            f"{where}{key}: must be a number {declared.describe_range()}, got {described(value)}"
        )
    scale = declared.scale if key == declared.key else 1.0
    try:
        return declared.validate(value * scale)
    except ParameterError as exc:
        raise InputsError(f"{where}{key}: {exc}") from None


def _object(data: Mapping[str, Any], key: str, where: str) -> dict[str, Any]:
    value = data.get(key)
    if not isinstance(value, dict):
        raise InputsError(f"{where}{key}: expected a JSON object, got {described(value)}")
    return value


def _no_unknown(data: Mapping[str, Any], known: set[str], where: str) -> None:
    """A misspelled key is an error, never silently ignored."""
    extra = sorted(set(data) - known)
    if extra:
        raise InputsError(
            f"{where}{printable(extra[0], 60)}: unknown key (known: {', '.join(sorted(known))})"
        )


def _keys(*declarations: Parameter) -> set[str]:
    return {key for declared in declarations for key in (declared.key, si_key(declared))}


def _settings(given: dict[str, Any], cls: type[Plugin], where: str) -> dict[str, Any]:
    """Settings by name [SI] from a settings record (:func:`_settings_record`)."""
    declarations = cls.setting_declarations()
    _no_unknown(given, _keys(*declarations.values()), where)
    out = {}
    for name, declared in declarations.items():
        keys = [key for key in _keys(declared) if key in given]
        if not keys:
            continue  # the default
        value = given[keys[0]]
        number = isinstance(value, int | float) and not isinstance(value, bool)
        if number and declared.kind is float and declared.convert is None:
            out[name] = _read_quantity(given, declared, where)
        else:
            out[name] = value  # the plug-in's declaration checks and converts it
    return out


def read_simulation(data: Mapping[str, Any], where: str, *, registry: PluginRegistry) -> Simulation:
    """The simulation of a model record (:func:`model_record`), its plug-ins from
    ``registry``."""
    known = {*KINDS, *(f"{k}_{part}" for k in KINDS for part in ("version", "settings"))}
    _no_unknown(data, known | _keys(REST_SPEED_FRACTION), where)
    names = {}
    for kind in KINDS:
        name = data.get(kind)
        if not isinstance(name, str):
            raise InputsError(f"{where}{kind}: expected a plug-in name, got {described(name)}")
        names[kind] = name
    settings = {
        kind: _settings(
            _object(data, f"{kind}_settings", where),
            registry.get(kind, names[kind]),
            f"{where}{kind}_settings.",
        )
        for kind in KINDS
    }
    return Simulation.from_names(
        names["resistance"],
        names["failure"],
        names["integrator"],
        resistance_settings=settings["resistance"],
        failure_settings=settings["failure"],
        integrator_settings=settings["integrator"],
        rest_speed_fraction=_read_quantity(data, REST_SPEED_FRACTION, where),
        registry=registry,
    )


@attrs.frozen
class RunInputs:
    """One scene, the simulation that ran it and its plate's label, read back."""

    scene: Scene
    simulation: Simulation
    label: str


def read_run_inputs(data: object, source: str, *, registry: PluginRegistry) -> RunInputs:
    """The scene and simulation of ``run --json``'s output or of its ``inputs`` object,
    plug-ins and plate keys from ``registry``;
    :class:`~plateimpact.base.errors.InputsError` names ``source`` and the key."""
    if isinstance(data, dict) and isinstance(data.get("inputs"), dict):
        data = data["inputs"]
    if not isinstance(data, dict) or data.get("format") != FORMAT:
        found = data.get("format") if isinstance(data, dict) else type(data).__name__
        raise InputsError(
            f"{source}: not a plateimpact inputs record (format {found!r:.60}, expected "
            f"{FORMAT!r}, as 'plateimpact run --json' writes)"
        )
    where = f"{source}: "
    scene_keys = _keys(IMPACT_SPEED, IMPACT_OBLIQUITY)
    _no_unknown(data, {*RECORD_ONLY, *scene_keys, "sphere", "plate", "model"}, where)
    sphere_data = _object(data, "sphere", where)
    _no_unknown(sphere_data, _keys(RADIUS, MASS), f"{where}sphere.")
    try:
        sphere = Sphere(
            radius=_read_quantity(sphere_data, RADIUS, f"{where}sphere."),
            mass=_read_quantity(sphere_data, MASS, f"{where}sphere."),
        )
        plate_data = _object(data, "plate", where)
        plate = plate_from_dict(plate_data, f"{source}: plate", registry=registry)
        model_data = _object(data, "model", where)
        simulation = read_simulation(model_data, f"{where}model.", registry=registry)
        scene = Scene(
            sphere,
            plate,
            _read_quantity(data, IMPACT_SPEED, where),
            _read_quantity(data, IMPACT_OBLIQUITY, where),
        )
    except (ParameterError, UnknownNameError, PluginError) as exc:
        raise InputsError(f"{source}: {exc}") from None
    label = data.get("label")
    return RunInputs(scene, simulation, label if isinstance(label, str) else source)


def load_run_inputs(path: str | os.PathLike[str], *, registry: PluginRegistry) -> RunInputs:
    """The scene and simulation recorded in a file (``run --json``'s output)."""
    data = load_json_file(path, InputsError)  # bounded: nesting, digits, size, duplicates
    return read_run_inputs(data, printable(os.fspath(path), 200), registry=registry)
