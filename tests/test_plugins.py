"""Plug-in discovery: built-ins and third-party packages through the same entry-point group."""

from __future__ import annotations

import json
import os
import subprocess
import sys
import types
from pathlib import Path

import numpy as np
import pluggy
import pytest

import plateimpact as pi
from plateimpact import presets

ROOT = Path(__file__).resolve().parents[1]
THIRD_PARTY = Path(__file__).resolve().parent / "third_party"


def test_builtins_arrive_only_through_the_entry_point_group():
    assert pi.load_registry(entry_points=False).names("resistance") == []
    registry = pi.load_registry()
    assert {"poncelet"} <= set(registry.names("resistance"))
    assert {"plugging", "intact"} <= set(registry.names("failure"))
    assert {"segment"} <= set(registry.names("integrator"))


def test_third_party_package_is_used_by_name(with_third_party, sphere):
    registry = pi.load_registry()
    assert "isotropic-poncelet" in registry.names("resistance")
    plate = presets.plate("6061-T6/9.53")
    results = {}
    for law in ("poncelet", "isotropic-poncelet"):
        # one path for both (the identity below is exact on either)
        simulation = pi.Simulation.from_names(resistance=law, registry=registry, engine="numpy")
        results[law] = simulation.run_batch(
            [pi.Scene(sphere, plate, 400.0, 0.0), pi.Scene(sphere, plate, 400.0, np.radians(45))]
        )
    # At normal incidence ψ ≡ 0, so both laws are eq 1 exactly; at 45° the isotropic
    # law resists more (no cos²ψ reduction): the ricochet is shallower and shorter.
    a, b = results["poncelet"], results["isotropic-poncelet"]
    assert a.max_penetration[0] == b.max_penetration[0]
    assert b.outcome[1] == a.outcome[1] == pi.Outcome.RICOCHET
    assert b.max_penetration[1] < a.max_penetration[1]
    assert b.contact_time[1] < a.contact_time[1]


def test_third_party_package_works_from_the_command_line(sphere):
    env = {**os.environ, "PYTHONPATH": os.pathsep.join([str(THIRD_PARTY), *sys.path])}
    command = [
        sys.executable,
        "-m",
        "plateimpact.cli",
        "run",
        "--preset",
        "2024-T3/6.35",
        "--speed",
        "500",
        "--obliquity",
        "30",
        "--resistance",
        "isotropic-poncelet",
        "--json",
    ]
    done = subprocess.run(command, capture_output=True, text=True, env=env, check=True)
    assert json.loads(done.stdout)["model"]["resistance"] == "isotropic-poncelet"


def test_misspelled_hook_is_rejected():
    hookimpl = pluggy.HookimplMarker("plateimpact")
    plugin = types.SimpleNamespace(plateimpact_regster=hookimpl(lambda registry: None))
    with pytest.raises(pluggy.PluginValidationError):
        pi.load_registry(entry_points=False, plugins=[plugin])


def test_a_name_taken_twice_is_an_error():
    registry = pi.load_registry()
    impostor = type("Impostor", (pi.ResistanceLaw,), {"name": "poncelet", "stress": None})
    with pytest.raises(pi.PluginError, match="registered twice"):
        registry.add(impostor)


def test_unknown_names_and_settings_list_the_choices():
    registry = pi.load_registry()
    with pytest.raises(pi.UnknownNameError, match="choose from: .*segment"):
        registry.create("integrator", "rk99")
    with pytest.raises(pi.ParameterError, match="settings: max_seconds, max_steps, step"):
        registry.create("integrator", "segment", tolerance=1e-6)
