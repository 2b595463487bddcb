"""The command line's one pattern (issue 22, item 5): every command a module of
``cli/commands`` with ``arguments(parser, registry)`` and ``run(args, registry, out)``,
listed in one table and imported only when invoked; output through one writer; human
units from the declarations, never a factor written in ``cli/``."""

from __future__ import annotations

import ast
import importlib
import inspect
import json
import re
import subprocess
import sys
from pathlib import Path

import pytest

from plateimpact.cli.commands import COMMANDS

CLI = Path(__file__).resolve().parents[1] / "framework" / "plateimpact" / "cli"
#: What a child prints: the plateimpact modules and the heavy libraries it imported.
PROBE = """
import json, sys
from plateimpact.cli import main
try:
    code = main(sys.argv[1:])
except SystemExit as exc:
    code = exc.code
loaded = sorted(m for m in sys.modules if m.startswith(("plateimpact.cli.commands.", "numpy",
    "scipy", "h5py", "matplotlib", "xarray", "plateimpact_plugins", "numba")))
print(json.dumps({"code": code, "loaded": loaded}), file=sys.stderr)
"""


def _loaded(*argv: str) -> tuple[int, set[str]]:
    done = subprocess.run(
        [sys.executable, "-c", PROBE, *argv], capture_output=True, text=True, timeout=120
    )
    found = json.loads(done.stderr.strip().splitlines()[-1])
    return found["code"], {
        name.split(".")[0] if "cli" not in name else name for name in found["loaded"]
    }


def test_every_command_is_one_module_with_arguments_and_run():
    modules = {path.stem for path in (CLI / "commands").glob("*.py")} - {"__init__"}
    assert modules == {command.module for command in COMMANDS}
    assert len({c.name for c in COMMANDS}) == len(COMMANDS)
    for command in COMMANDS:
        module = importlib.import_module(f"plateimpact.cli.commands.{command.module}")
        assert list(inspect.signature(module.arguments).parameters) == ["p", "registry"] or list(
            inspect.signature(module.arguments).parameters
        ) == ["parser", "registry"], command
        assert list(inspect.signature(module.run).parameters) == ["args", "registry", "out"]


@pytest.mark.parametrize("argv", [["--version"], ["--help"], ["run", "--help"]])
def test_version_and_help_import_no_numeric_library_and_at_most_the_command_asked(argv):
    code, loaded = _loaded(*argv)
    assert code == 0
    commands = {name for name in loaded if name.startswith("plateimpact.cli.commands.")}
    if argv[0] == "run":
        assert commands == {"plateimpact.cli.commands.run"}
    else:  # the table names the commands: none is imported, nor numpy
        assert commands == set() and loaded == set()


def test_run_imports_its_module_only_and_no_scipy_h5py_matplotlib_xarray():
    code, loaded = _loaded("run", "--preset", "2024-T3/3.18", "--speed", "640", "--obliquity", "60")
    assert code == 0
    assert {n for n in loaded if n.startswith("plateimpact.cli")} == {
        "plateimpact.cli.commands.run"
    }
    assert not loaded & {"h5py", "matplotlib", "xarray"}
    # scipy only as numba's import, where the scene runs compiled (as a sweep's rows do,
    # so that `run --inputs` reruns a row to the same bits)
    assert "scipy" not in loaded or "numba" in loaded


def _sources() -> dict[Path, str]:
    return {path: path.read_text() for path in CLI.rglob("*.py")}


#: A unit factor written out: 1e3, 1e-3, 1e6, 1e-6, 180 (degrees per pi), pi, or a
#: conversion function; cli/ formats through plateimpact.cli.formatting instead.
UNIT_FACTOR = re.compile(
    r"\b1e-?[36]\b|\b180(\.0)?\b|\b(math|np|numpy)\.pi\b|\b(degrees|radians)\("
)


def test_no_unit_factor_is_written_in_the_cli():
    found = [
        f"{path.relative_to(CLI)}:{number}: {line.strip()}"
        for path, text in _sources().items()
        for number, line in enumerate(text.splitlines(), 1)
        if UNIT_FACTOR.search(line.split("#", 1)[0])
    ]
    assert found == []


def test_all_output_goes_through_the_writer():
    """No print and no direct write to sys.stdout/sys.stderr outside cli/writer.py."""
    found = []
    for path, text in _sources().items():
        if path.name == "writer.py":
            continue
        for node in ast.walk(ast.parse(text)):
            if isinstance(node, ast.Call) and isinstance(node.func, ast.Name):
                if node.func.id == "print":
                    found.append(f"{path.name}:{node.lineno}: print")
            if (
                isinstance(node, ast.Attribute)
                and node.attr == "write"
                and isinstance(node.value, ast.Attribute)
                and node.value.attr in ("stdout", "stderr")
            ):
                found.append(f"{path.name}:{node.lineno}: sys.{node.value.attr}.write")
    assert found == []


def test_the_formatter_reads_units_and_scales_from_the_declaration():
    """Against independent arithmetic: 3.2 mm is 3.2e-3 m; 60 deg is pi/3 rad; 45.3 us."""
    import math

    from plateimpact.cli.formatting import DURATION, quantity
    from plateimpact.model.results import RESULT_FIELDS
    from plateimpact.model.scene import IMPACT_OBLIQUITY, IMPACT_SPEED

    assert quantity(RESULT_FIELDS["max_penetration"], 3.2e-3) == "3.2 mm"
    assert quantity(IMPACT_OBLIQUITY, math.pi / 3) == "60 deg"
    assert quantity(IMPACT_SPEED, 640.0) == "640 m/s"
    assert quantity(DURATION, 45.3e-6, 3) == "45.3 us"
    assert quantity(RESULT_FIELDS["outcome"], 2.0) == "2"  # a pure number: no unit
