"""No global registry in the library (issue 22, item 4): the installed plug-ins
(``default_registry()``) are resolved only at the API's top, listed in docs/plugins.md
("Where the registry comes from"); everything below takes a registry, or a Simulation
that carries one. ``plateimpact run`` without ``--json`` does no provenance work."""

from __future__ import annotations

import ast
import json
import math
import shutil
import subprocess
from pathlib import Path

import pytest

import plateimpact as pi
from plateimpact.cli import main

CORE = Path(__file__).resolve().parents[1] / "framework" / "plateimpact"
FORMAT1 = Path(__file__).parent / "data" / "format1.h5"
#: Where ``default_registry`` may be named: its definition and export, the command
#: line's main (it builds the one registry of a command), and the API's entry points.
ENTRY_POINTS = {
    "registry/plugin_registry.py": {"default_registry"},
    "__init__.py": {"<module>", "__dir__", "__getattr__"},  # the moved names, deprecated
    "cli/__init__.py": {"build_parser", "main"},
    "registry/presets.py": {"plate", "__getattr__"},  # pi.presets: the installed presets
    "run/simulation.py": {"Simulation", "Simulation.from_names"},
    "run/variant.py": {"Variant", "Variant.__attrs_post_init__"},  # default plug-ins
    "storage/plate_file.py": {"load_plate_file", "save_plate_file"},
    # preset names, sphere; the plate constants' units of a study's tables
    "study/study.py": {"Study.grid", "StudyResults.to_xarray", "StudyResults.to_dataframe"},
}


def _users(tree: ast.AST) -> set[str]:
    """The qualified names of the functions and classes whose code names default_registry
    (``<module>`` for module level, imports aside)."""
    found: set[str] = set()

    def visit(node: ast.AST, where: list[str]) -> None:
        for child in ast.iter_child_nodes(node):
            if isinstance(child, ast.FunctionDef | ast.AsyncFunctionDef | ast.ClassDef):
                visit(child, [*where, child.name])
                continue
            named = (isinstance(child, ast.Name) and child.id == "default_registry") or (
                isinstance(child, ast.Attribute) and child.attr == "default_registry"
            )
            if named:
                found.add(".".join(where) or "<module>")
            visit(child, where)

    visit(tree, [])
    return found


def test_only_the_documented_entry_points_name_default_registry():
    found = {}
    for path in CORE.rglob("*.py"):
        text = path.read_text()
        if "default_registry" in text:
            users = _users(ast.parse(text))
            if users:
                found[path.relative_to(CORE).as_posix()] = users
    assert {k: v for k, v in found.items() if not v <= ENTRY_POINTS.get(k, set())} == {}


@pytest.fixture
def no_global(monkeypatch):
    """default_registry raising wherever the library could reach it."""

    def refuse() -> pi.PluginRegistry:
        raise AssertionError("the library reached for the global registry")

    import importlib
    import sys

    # Every module that names it imported first: one imported while it is replaced would
    # keep the replacement after the test.
    for where in ENTRY_POINTS:
        importlib.import_module(
            ".".join(
                ["plateimpact", *where.split("/")[:-1]]
                + ([] if where.endswith("__init__.py") else [where.split("/")[-1][:-3]])
            )
        )
    for name, module in list(sys.modules.items()):
        if name.startswith("plateimpact") and hasattr(module, "default_registry"):
            monkeypatch.setattr(module, "default_registry", refuse)
    return pi.load_registry()


def test_the_library_runs_on_an_explicit_registry_alone(no_global, tmp_path, sphere):
    """Study runs appended to an archive, exported as netCDF and CSV, a plate file written
    and read, limits found, stored, read back and printed, run inputs recorded and read
    back, a format-1 archive upgraded: each with the registry handed to it."""
    from plateimpact.provenance.inputs import read_run_inputs
    from plateimpact.provenance.metadata import inputs_record
    from plateimpact.storage import export, plate_file
    from plateimpact.storage.upgrade import upgrade

    registry = no_global
    plate = registry.plate("2024-T3/3.18")  # the presets are the registry's
    simulation = pi.Simulation.from_names(registry=registry)
    assert simulation.registry is registry
    # a Variant naming no plug-in takes the installed defaults: name them from this one
    names = [registry.default(kind) for kind in ("resistance", "failure", "integrator")]
    variant = pi.Variant("v", *names)
    study = pi.Study.grid("s", [plate], [0.0, 45.0], [400.0, 900.0], variant, registry=registry)
    archive = tmp_path / "a.h5"
    assert len(study.run(archive=archive, registry=registry)["v"]) == 4
    run = pi.Archive(archive).runs()[0]
    assert export.netcdf_bytes(pi.Archive(archive), run, registry=registry).startswith(b"\x89HDF")
    rows = list(export.table_rows(pi.Archive(archive), run, registry=registry))
    assert len(rows) == 4
    path = tmp_path / "plate.json"
    plate_file.save_plate_file(path, plate, registry=registry)
    assert pi.load_plate_file(path, registry) == plate
    found = pi.limits.along_speed(simulation, sphere, plate, [math.radians(45)], (300.0, 900.0))
    pi.limits.archive_limits(archive, "l", found)
    back = pi.limits.read_limits(archive, "l", registry)
    assert back.to_json()["plate"] == found.to_json()["plate"]
    scene = pi.Scene(sphere, plate, 640.0, math.radians(60))
    record = inputs_record(simulation, sphere, plate, label="x", scene={})
    record.update({"impact_speed_m_s": 640.0, "impact_obliquity_deg": 60.0})
    again = read_run_inputs(record, "record", registry=registry)
    assert again.scene.plate == plate and again.scene.impact_speed == scene.impact_speed
    old = tmp_path / "old.h5"
    shutil.copy(FORMAT1, old)
    upgrade(old, registry=registry)
    assert pi.Archive(old).version() == 2


RUN = ["run", "--preset", "2024-T3/3.18", "--speed", "640", "--obliquity", "60"]


def test_run_without_json_does_no_provenance_work(monkeypatch, capsys):
    """No git subprocess, no source hashing, no inputs record for the text output."""

    def refuse(*args: object, **kwargs: object) -> None:
        raise AssertionError("provenance work for the text output")

    monkeypatch.setattr(subprocess, "Popen", refuse)
    monkeypatch.setattr("plateimpact.provenance.metadata.inputs_record", refuse)
    monkeypatch.setattr("plateimpact.provenance.code.plugins_record", refuse)
    monkeypatch.setattr("plateimpact.provenance.metadata.source_commit", refuse)
    assert main(RUN) == 0
    assert "-> ricochet" in capsys.readouterr().out


def test_run_with_json_still_records_its_inputs_and_provenance(capsys):
    assert main([*RUN, "--json"]) == 0
    inputs = json.loads(capsys.readouterr().out)["inputs"]
    assert {"source_commit", "plugins", "versions", "plate", "model"} <= set(inputs)
