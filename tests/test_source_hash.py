"""Which modules a source hash covers: every module imported anywhere a statement can
run (a function, a class, a try, a with, a match case, an else), never one imported only
under ``if TYPE_CHECKING:`` (provenance.source_hash)."""

from __future__ import annotations

import sys
import textwrap

import pytest

from plateimpact.provenance.source_hash import module_sources

ROOT = textwrap.dedent(
    """
    from __future__ import annotations
    from typing import TYPE_CHECKING
    from . import at_top
    if TYPE_CHECKING:
        from . import only_typed
    else:
        from . import in_else

    def f():
        from . import in_function
        return [lambda: None for _ in ()]

    class C:
        from . import in_class

    try:
        import pkgx.in_try
    except ImportError:
        from .in_handler import name
    finally:
        from . import in_finally

    with open(__file__):
        from . import in_with

    match 1:
        case 1:
            from . import in_case

    value = (lambda: __import__("pkgx.by_call"))  # a call is not an import statement
    """
)
FOUND = ("at_top", "in_else", "in_function", "in_class", "in_try", "in_handler",
         "in_finally", "in_with", "in_case")  # fmt: skip
NOT_FOUND = ("only_typed", "by_call")


@pytest.fixture
def package(tmp_path, monkeypatch):
    root = tmp_path / "pkgx"
    root.mkdir()
    (root / "__init__.py").write_text("")
    (root / "root.py").write_text(ROOT)
    for name in FOUND + NOT_FOUND:
        (root / f"{name}.py").write_text("name = 1\n")
    monkeypatch.syspath_prepend(str(tmp_path))
    yield "pkgx"
    for name in [m for m in sys.modules if m == "pkgx" or m.startswith("pkgx.")]:
        del sys.modules[name]


def test_imports_in_every_kind_of_block_are_covered_and_typing_only_ones_are_not(package):
    names = {name for name, _ in module_sources(["pkgx.root"], ["pkgx"])}
    assert names == {"pkgx", "pkgx.root", *(f"pkgx.{name}" for name in FOUND)}
