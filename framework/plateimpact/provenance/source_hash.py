"""A hash of the code that defines a class: its module and, transitively, every module
that module imports from the packages followed (docs/archive.md, "Provenance").

The hash is SHA-256 over the sorted lines ``MODULE SHA256-OF-ITS-FILE``: module names,
not paths, and each file's bytes as they are, so an editable install, a wheel install
and a source tree on ``sys.path`` of the same code hash alike, wherever they sit. The
imports are read from each module's source (``import a.b``, ``from .c import d``, also
inside functions), with every enclosing package's ``__init__``. Not seen: a module
imported by a computed name (``importlib.import_module(name)``), data files a module
reads, and whatever a compiled extension does beyond its own file's bytes; packages
not followed (numpy, scipy: their versions are recorded apart).
"""

from __future__ import annotations

import ast
import hashlib
import importlib.util
import sys
from collections.abc import Iterable
from importlib.machinery import ModuleSpec, PathFinder
from pathlib import Path


def module_sources(
    roots: Iterable[str], followed: Iterable[str]
) -> tuple[tuple[str, Path | None], ...]:
    """``(module, file)`` for each of ``roots``, every module they import from the
    ``followed`` packages (``"plateimpact_plugins"``, ``"plateimpact.limits"``: a
    package and what is inside it), transitively, and their enclosing packages, sorted
    by name; ``file`` is None for a module without one (built in, frozen, made by
    ``exec``).
    An enclosing package's ``__init__`` is hashed (importing ``a.b`` runs it), its own
    imports followed only where a module imports it by name. Read afresh at each call
    (provenance.code keeps one answer per class)."""
    roots, followed = tuple(roots), tuple(followed)
    found: dict[str, Path | None] = {}
    read: set[str] = set()  # the modules whose imports were followed
    pending = [(root, True) for root in roots]
    while pending:
        name, follow = pending.pop()
        if name not in found:
            if name not in roots and _spec(name) is None:
                continue  # not a module here (a guarded import of an optional one): never runs
            found[name] = _origin(name)
            parent = name.rpartition(".")[0]
            if parent:
                pending.append((parent, False))
        origin = found[name]
        if follow and name not in read and origin is not None and origin.suffix == ".py":
            read.add(name)
            package = name if origin.name == "__init__.py" else name.rpartition(".")[0]
            pending += [(m, True) for m in _imports(origin, package, followed)]
    return tuple(sorted(found.items()))


def source_sha256(sources: Iterable[tuple[str, Path | None]]) -> str | None:
    """The hash of :func:`module_sources`' answer (hex), or None when a module has no
    file or it cannot be read: then the code is not known, and says so."""
    lines = []
    for name, path in sources:
        digest = _file_sha256(path) if path is not None else None
        if digest is None:
            return None
        lines.append(f"{name} {digest}\n")
    return hashlib.sha256("".join(lines).encode()).hexdigest()


def _origin(name: str) -> Path | None:
    """The file module ``name`` is (or would be) loaded from, found without importing
    anything: its spec if loaded, else the finders', below its parent's search path; a
    script run as ``__main__`` has no spec, but its file."""
    spec = _spec(name)
    if spec is not None and spec.has_location and spec.origin:
        return Path(spec.origin)
    where = getattr(sys.modules.get(name), "__file__", None)
    return Path(where) if isinstance(where, str) else None


def _spec(name: str) -> ModuleSpec | None:
    module = sys.modules.get(name)
    if module is not None:
        return getattr(module, "__spec__", None)
    parent, _, _ = name.rpartition(".")
    try:
        if not parent:
            return importlib.util.find_spec(name)  # a top-level name imports nothing
        above = _spec(parent)
        where = above.submodule_search_locations if above is not None else None
        return PathFinder.find_spec(name, list(where)) if where is not None else None
    except (ImportError, ValueError, AttributeError):  # not importable: nothing to hash
        return None


def _inside(name: str, followed: tuple[str, ...]) -> bool:
    return any(name == package or name.startswith(f"{package}.") for package in followed)


def _imports(path: Path, package: str, followed: tuple[str, ...]) -> set[str]:
    """The modules of the ``followed`` packages that the source at ``path`` imports,
    absolute (``from a import b`` gives ``a``, and ``a.b`` if that is a module)."""
    try:
        tree = ast.parse(path.read_bytes(), str(path))
    except (OSError, SyntaxError, ValueError):
        return set()
    found: set[str] = set()
    for node in _executed(tree):
        if isinstance(node, ast.Import):
            found.update(a.name for a in node.names if _inside(a.name, followed))
        elif isinstance(node, ast.ImportFrom):
            base = _absolute(node.module or "", node.level, package)
            if base is None or not _inside(base, followed):
                continue
            found.add(base)
            found.update(
                f"{base}.{alias.name}"
                for alias in node.names
                if alias.name != "*" and _is_module(f"{base}.{alias.name}")
            )
    return found


def _absolute(module: str, level: int, package: str) -> str | None:
    if level == 0:
        return module
    try:
        return importlib.util.resolve_name("." * level + module, package)
    except (ImportError, ValueError):
        return None


def _is_module(name: str) -> bool:
    return _spec(name) is not None


#: The fields that hold blocks of statements (an import is a statement, so it sits in one
#: of these, at any depth, and never inside an expression).
_BLOCKS = ("body", "orelse", "finalbody", "handlers", "cases")


def _executed(tree: ast.AST) -> list[ast.AST]:
    """Every statement of ``tree`` (with the except clauses and match cases that hold
    them) but those under ``if TYPE_CHECKING:``, which never run. Expressions are not
    walked: they hold no imports, and walking them tripled the cost of a core hash."""
    nodes, pending = [], [tree]
    while pending:
        node = pending.pop()
        nodes.append(node)
        if isinstance(node, ast.If) and _type_checking(node.test):
            pending += node.orelse
            continue
        for field in _BLOCKS:
            block = getattr(node, field, None)
            if isinstance(block, list):  # a lambda's body is an expression
                pending += block
    return nodes


def _type_checking(test: ast.expr) -> bool:
    name = test.attr if isinstance(test, ast.Attribute) else getattr(test, "id", None)
    return name == "TYPE_CHECKING"


def _file_sha256(path: Path) -> str | None:
    try:
        with path.open("rb") as file:
            return hashlib.file_digest(file, "sha256").hexdigest()
    except OSError:
        return None
