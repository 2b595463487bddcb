"""The package's shape: its folders are its layers, imported downward without cycles;
short modules; cheap imports.

Each folder of the core is one layer or one capability, and a module's layer is its
folder's name. LAYERS orders the folders, lowest first; the folders of one entry share a
layer (the analysis capabilities). A module imports its own folder or a lower layer's,
never a higher one, never the package root (the root re-exports, lazily: it and the
``units`` module beside it are the public face, which nothing inside imports), never the
built-in plug-ins or the studies. Folders that share a layer import one another without a
cycle.
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
#: The folders of the core, lowest layer first.
LAYERS: list[tuple[str, ...]] = [
    ("base",),  # unit factors, errors, untrusted input, declarations of parameters
    ("model",),  # bodies, scenes, geometry, the physics' plug-in contracts, the model
    ("solve",),  # the integrator contract, the driver, step control, events
    ("registry",),  # the plug-ins' hook, discovery, the registry
    ("run",),  # simulations, variants, progress
    ("storage",),  # archives, netCDF, locks, plate and shot files, outputs, export
    ("provenance",),  # what produced a result: inputs, versions, the code's hashes
    ("study", "limits", "v50", "calibration", "experiment", "comparison", "uncertainty"),
    ("figures",),  # every figure
    ("cli",),  # the command line
]
#: The package root: its lazy re-exports and the documented ``plateimpact.units``.
PUBLIC_FACE = ("plateimpact", "plateimpact.units")
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


def folder_of(name: str) -> str:
    """The folder a module of the core is in (its layer's name)."""
    return name.split(".")[1]


def layer_of(name: str) -> int:
    return next(i for i, folders in enumerate(LAYERS) if folder_of(name) in folders)


def test_every_folder_is_a_layer_and_every_module_is_in_a_folder():
    folders = {p.name for p in CORE.iterdir() if (p / "__init__.py").is_file()}
    assert folders == {folder for layer in LAYERS for folder in layer}
    loose = {p.stem for p in CORE.glob("*.py")} - {"__init__"}
    assert {f"plateimpact.{stem}" for stem in loose} == set(PUBLIC_FACE) - {"plateimpact"}


def test_no_module_imports_a_higher_layer_or_the_package_root():
    wrong = []
    for name, imported in GRAPH.items():
        if name in PUBLIC_FACE:
            continue  # the public face re-exports every layer
        for target in imported:
            if target in PUBLIC_FACE or not target.startswith("plateimpact."):
                wrong.append((name, target))
            elif layer_of(target) > layer_of(name):
                wrong.append((name, target))
    assert not wrong


def find_cycle(graph: dict[str, set[str]]) -> list[str] | None:
    """A cycle of ``graph`` (node -> the nodes it imports), or None."""
    state: dict[str, int] = {}  # 1 on the current path, 2 done

    def visit(node: str, path: list[str]) -> list[str] | None:
        state[node] = 1
        for nxt in sorted(graph.get(node, ())):
            if state.get(nxt) == 1:
                return path[path.index(nxt) :] + [nxt]
            if nxt not in state and (cycle := visit(nxt, [*path, nxt])):
                return cycle
        state[node] = 2
        return None

    for node in sorted(graph):
        if node not in state and (cycle := visit(node, [node])):
            return cycle
    return None


def test_no_import_cycles():
    graph = {n: {m for m in deps if m in CORE_MODULES} for n, deps in GRAPH.items()}
    cycle = find_cycle(graph)
    assert cycle is None, "import cycle: " + " -> ".join(cycle or [])


def test_folders_that_share_a_layer_import_one_another_without_a_cycle():
    folders: dict[str, set[str]] = {}
    for name, imported in GRAPH.items():
        if name not in PUBLIC_FACE:
            others = {folder_of(m) for m in imported if m in CORE_MODULES} - {folder_of(name)}
            folders.setdefault(folder_of(name), set()).update(others)
    cycle = find_cycle(folders)
    assert cycle is None, "folders import each other: " + " -> ".join(cycle or [])


def test_storage_runs_nothing():
    """Storage sits above run/ only because an archive records and reads back a run's
    Variant (plug-in names and settings): of run/ it imports that record, never the
    simulation, and nothing of a layer above."""
    used = {
        m
        for name, imported in GRAPH.items()
        if name.startswith("plateimpact.storage.")
        for m in imported
        if m.startswith("plateimpact.run")
    }
    assert used <= {"plateimpact.run.variant"}


def test_the_core_never_imports_plug_ins_or_studies_and_plug_ins_use_the_public_api():
    for path in (ROOT / "plugins").rglob("*.py"):
        for node in ast.walk(ast.parse(path.read_text())):
            names = []
            if isinstance(node, ast.ImportFrom) and not node.level:
                names = [node.module or ""]
            elif isinstance(node, ast.Import):
                names = [alias.name for alias in node.names]
            assert not [n for n in names if n.startswith("plateimpact.")], path
    for name, imported in GRAPH.items():  # every import named plateimpact*, parsed once
        foreign = {m for m in imported if m.startswith("plateimpact_")}
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
    found = {"plateimpact_studies"}  # and its folders of data files, packages to setuptools
    found |= {
        f"plateimpact_studies.{folder.name}"
        for folder in (ROOT / "studies").iterdir()
        if folder.is_dir() and not folder.name.startswith(("_", "."))
    }
    for package, root in roots.items():
        for init in root.rglob("__init__.py"):
            parts = init.parent.relative_to(root).parts
            found.add(".".join((package, *parts)))
    assert found == listed
