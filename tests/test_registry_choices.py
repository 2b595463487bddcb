"""Defaults, presets and the default sphere come from the plug-in packages through the
registry; the core names none of them (docs/plugins.md, "The report's vocabulary")."""

from __future__ import annotations

import math

import numpy as np
import pytest

import plateimpact as pi
from plateimpact import presets
from plateimpact_plugins.report import SAE1010_TABLE

BUILTINS = pi.default_registry()


def hooks(function):
    return type("Hooks", (), {"plateimpact_register": staticmethod(pi.hookimpl(function))})


def test_the_built_ins_declare_the_reports_model_as_the_defaults():
    assert BUILTINS.defaults == {
        "resistance": "poncelet",
        "failure": "plugging",
        "integrator": "dopri5",
    }
    model = pi.Simulation.from_names().model
    assert (model.resistance.name, model.failure.name) == ("poncelet", "plugging")
    variant = pi.Variant("v")
    assert (variant.resistance, variant.failure, variant.integrator) == (
        "poncelet", "plugging", "dopri5",
    )  # fmt: skip


def test_a_second_default_of_a_kind_is_refused_in_one_line():
    poncelet = BUILTINS.get("resistance", "poncelet")
    rate = type("Other", (poncelet,), {"name": "other-law"})

    def register(registry):
        registry.add(poncelet, default=True)
        registry.add(rate, default=True)

    with pytest.raises(pi.PluginError, match="default resistance claimed twice") as caught:
        pi.load_registry(entry_points=False, plugins=[hooks(register)])
    assert "\n" not in str(caught.value)


def test_without_a_declared_default_a_name_is_required():
    registry = pi.load_registry(entry_points=False)
    with pytest.raises(pi.UnknownNameError, match="no default resistance"):
        pi.Simulation.from_names(registry=registry)
    with pytest.raises(pi.UnknownNameError, match="unknown preset '2024-T3/3.18'; choose"):
        registry.plate("2024-T3/3.18")
    with pytest.raises(pi.UnknownNameError, match="no default sphere"):
        registry.sphere  # noqa: B018


def test_presets_are_table_1_through_the_registry():
    # Table 1 of the report, typed from the report: a [N/m²], b [kg/m³], P* [mm].
    table_1 = {
        "2024-T3/1.27": (1.27, 0.272e9, 0.129e4, 2.2),
        "2024-T3/3.18": (3.18, 0.101e10, 0.126e4, 3.0),
        "2024-T3/6.35": (6.35, 0.933e9, 0.974e3, 6.4),
        "6061-T6/9.53": (9.52, 0.112e10, 0.580e3, 7.5),
        "SAE1010/1.47": (1.47, 0.380e9, 0.148e4, 4.6),
    }
    assert list(presets.PLATES) == list(table_1) == list(BUILTINS.plates)
    for name, (thickness_mm, a, b, pstar_mm) in table_1.items():
        plate = presets.plate(name)
        assert plate is BUILTINS.plate(name)
        assert (plate.thickness, plate.a, plate.b) == (thickness_mm * 1e-3, a, b)
        assert plate.critical_penetration == pstar_mm * 1e-3
        assert plate.failure_angle == math.radians(45.0)
    sphere = presets.DEFAULT_SPHERE
    assert sphere.radius == 0.5 * 6.35e-3
    assert sphere.mass == pytest.approx(4.0 / 3.0 * math.pi * sphere.radius**3 * 7830.0)
    assert presets.SPHERE_DENSITY == 7830.0


def test_a_preset_registered_twice_differently_is_refused_and_a_failed_hook_leaves_none():
    plate = BUILTINS.plate("2024-T3/3.18")

    def clash(registry):
        registry.add_plate("p", plate)
        registry.add_plate("p", plate.with_constants(a=2e9))

    with pytest.raises(pi.PluginError, match="preset 'p' is registered twice"):
        pi.load_registry(entry_points=False, plugins=[hooks(clash)])
    registry = pi.load_registry(entry_points=False)
    with pytest.raises(RuntimeError), registry._all_or_nothing([]):
        registry.add_plate("p", plate)
        registry.set_sphere(BUILTINS.sphere, density=7830.0, material="steel")
        raise RuntimeError("the hook fails after its presets")
    assert registry.plates == {}
    with pytest.raises(pi.UnknownNameError):
        registry.sphere  # noqa: B018


def test_a_table_setting_is_held_as_its_declared_json_form():
    variant = pi.Variant("v", failure="variable-pstar", failure_settings={"table": SAE1010_TABLE})
    rows = variant.failure_settings["table"]
    # The report's SAE 1010 values (Figures 38-44), in the table's user units (through
    # radians and back: to the last bit or two).
    expected = [[0.0, 4.6, 4.6, 300.0, 330.0], [45.0, 3.5, 4.4, 330.0, 420.0],
                [60.0, 3.0, 3.8, 430.0, 550.0]]  # fmt: skip
    assert np.array(rows) == pytest.approx(np.array(expected), rel=1e-15)
    assert pi.Variant.from_json(variant.to_json()) == variant
    numpy_settings = pi.Variant("w", integrator_settings={"rtol": np.float64(1e-9)})
    assert numpy_settings.integrator_settings == {"rtol": 1e-9}
    with pytest.raises(pi.ParameterError, match="is not a JSON value"):
        pi.Variant("x", integrator_settings={"rtol": object()})


def test_the_moved_calibration_names_still_work_deprecated_through_the_registry():
    from plateimpact_plugins.report import fits  # noqa: PLC0415

    for name in ("calibrate", "newton_fit", "fit_pstar", "PstarTableFit"):
        with pytest.warns(DeprecationWarning, match=f"plateimpact.{name} is deprecated: import"):
            assert getattr(pi, name) is getattr(fits, name)
    assert BUILTINS.procedure("calibration") is fits
    with pytest.raises(pi.UnknownNameError, match="no installed plug-in package provides"):
        pi.load_registry(entry_points=False).procedure("calibration")


def test_a_registry_that_ran_a_procedure_still_goes_to_a_worker_process():
    import pickle  # noqa: PLC0415

    registry = pi.load_registry()
    registry.procedure("calibration")  # loaded: a module, which does not pickle
    again = pickle.loads(pickle.dumps(registry))
    assert again.defaults == registry.defaults and again.plates == registry.plates
    assert again.procedure("calibration") is registry.procedure("calibration")
