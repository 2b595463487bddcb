"""The package's shape: import layers without cycles, short modules, cheap imports.

Layers, lowest first: physics (the model's data, geometry, interfaces, the model) <-
running (driver, steppers' interface, registry, simulation) <- storage (archives, plate
and shot files) <- analysis (studies, calibration, plotting) <- cli. A module imports its
own layer or lower ones, never the package root, never the built-in plug-ins.
"""

from __future__ import annotations

import ast
import os
import subprocess
import sys
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[1]
CORE = ROOT / "framework" / "plateimpact"
LAYERS = {
    "physics": {"base", "units", "model"},
    "running": {
        "solve", "registry", "run",
    },
    "storage": {"storage", "provenance"},
    "analysis": {
        "study", "comparison", "calibration", "figures", "limits",
        "experiment", "v50",
    },
    "cli": {"cli"},
}  # fmt: skip
ORDER = list(LAYERS)
LONGEST_MODULE = 400  # lines


def modules(root: Path, package: str) -> dict[str, Path]:
    found = {}
    for path in root.rglob("*.py"):
        parts = path.relative_to(root).with_suffix("").parts
        name = ".".join((package, *parts)).removesuffix(".__init__")
        found[name] = path
    return found


CORE_MODULES = modules(CORE, "plateimpact")


def imports_of(name: str, path: Path) -> set[str]:
    """The modules of the core that ``name`` imports (a submodule where one is named)."""
    package = name if path.name == "__init__.py" else name.rsplit(".", 1)[0]
    found = set()
    for node in ast.walk(ast.parse(path.read_text())):
        if isinstance(node, ast.Import):
            found |= {alias.name for alias in node.names}
        elif isinstance(node, ast.ImportFrom):
            if node.level:
                base = package.split(".")[: len(package.split(".")) - node.level + 1]
                target = ".".join(base + ([node.module] if node.module else []))
            else:
                target = node.module or ""
            named = {f"{target}.{alias.name}" for alias in node.names}
            subs = named & set(CORE_MODULES)
            found |= subs or {target}
    return found


GRAPH = {
    name: {m for m in imports_of(name, path) if m.startswith("plateimpact")} - {name}
    for name, path in CORE_MODULES.items()
}


def layer_of(name: str) -> str:
    top = name.split(".")[1]
    return next(layer for layer, members in LAYERS.items() if top in members)


def test_every_module_has_a_layer():
    inner = [name for name in CORE_MODULES if name != "plateimpact"]
    assert all(layer_of(name) for name in inner)


def test_no_module_imports_a_higher_layer_or_the_package_root():
    wrong = []
    for name, imported in GRAPH.items():
        if name == "plateimpact":
            continue  # the root re-exports everything, lazily
        for target in imported:
            if target == "plateimpact" or not target.startswith("plateimpact."):
                wrong.append((name, target))
            elif ORDER.index(layer_of(target)) > ORDER.index(layer_of(name)):
                wrong.append((name, target))
    assert not wrong


def test_no_import_cycles():
    graph = {
        n: {m for m in deps if m in CORE_MODULES and m != "plateimpact"}
        for n, deps in GRAPH.items()
    }
    state: dict[str, int] = {}  # 1 on the current path, 2 done

    def visit(node: str, path: list[str]) -> None:
        state[node] = 1
        for nxt in graph[node]:
            if state.get(nxt) == 1:
                pytest.fail("import cycle: " + " -> ".join(path[path.index(nxt) :] + [nxt]))
            if nxt not in state:
                visit(nxt, [*path, nxt])
        state[node] = 2

    for node in graph:
        if node not in state:
            visit(node, [node])


def test_the_core_never_imports_plug_ins_or_studies_and_plug_ins_use_the_public_api():
    for path in (ROOT / "plugins").rglob("*.py"):
        for node in ast.walk(ast.parse(path.read_text())):
            names = []
            if isinstance(node, ast.ImportFrom) and not node.level:
                names = [node.module or ""]
            elif isinstance(node, ast.Import):
                names = [alias.name for alias in node.names]
            assert not [n for n in names if n.startswith("plateimpact.")], path
    for name, path in CORE_MODULES.items():
        foreign = {m for m in imports_of(name, path) if m.startswith("plateimpact_")}
        assert not foreign, name


@pytest.mark.parametrize("folder", ["framework", "plugins"])
def test_no_module_is_over_400_lines(folder):
    long = {
        str(p.relative_to(ROOT)): n
        for p in (ROOT / folder).rglob("*.py")
        if (n := len(p.read_text().splitlines())) > LONGEST_MODULE
    }
    assert not long


def run_python(code: str, **env: str) -> str:
    done = subprocess.run(
        [sys.executable, "-c", code],
        capture_output=True,
        text=True,
        check=True,
        env={**os.environ, **env},
    )
    return done.stdout.strip()


def test_importing_the_package_loads_none_of_its_heavy_dependencies():
    heavy = ("numpy", "scipy", "h5py", "matplotlib", "pluggy", "tqdm")
    code = f"import sys, plateimpact; print([m for m in {heavy!r} if m in sys.modules])"
    assert run_python(code) == "[]"


def test_figures_leave_the_users_matplotlib_backend_alone():
    figures = sorted(p.stem for p in (CORE / "figures").glob("*.py") if p.stem != "__init__")
    code = (
        "import importlib, matplotlib; before = matplotlib.get_backend(); "
        f"[importlib.import_module('plateimpact.figures.' + m) for m in {figures!r}]; "
        "import matplotlib.pyplot as plt; print(before, plt.get_backend())"
    )
    assert run_python(code, MPLBACKEND="svg") == "svg svg"


def test_every_package_directory_is_installed():
    """A non-editable install ships only the packages pyproject.toml lists (CI installs so)."""
    import tomllib

    listed = set(
        tomllib.loads((ROOT / "pyproject.toml").read_text())["tool"]["setuptools"]["packages"]
    )
    roots = {"plateimpact": CORE, "plateimpact_plugins": ROOT / "plugins" / "plateimpact_plugins"}
    found = {"plateimpact_studies"}
    for package, root in roots.items():
        for init in root.rglob("__init__.py"):
            parts = init.parent.relative_to(root).parts
            found.add(".".join((package, *parts)))
    assert found == listed
