"""The core names no built-in plug-in, none of the report's constants, table format or
presets: they live in the plug-in package (``plateimpact_plugins.report`` and the
plug-ins), which registers them; the core reads them from the registry (issue 22, item 2).

What is checked: every NAME token and every string literal of ``framework/`` that is not
a docstring (f-string parts included, and each word of a literal), against the names
below. Not checked: the one-letter constants ``a`` and ``b`` (as words they are too
common: the core's ``"a"``/``"b"`` are the two runs a comparison compares). Comments and
docstrings may cite the report (its equations, Table 1, the plug-ins as examples): they are prose,
not code. The names come from the plug-in package itself, so a built-in added there is
checked too.
"""

from __future__ import annotations

import ast
import io
import re
import tokenize
from pathlib import Path

import plateimpact as pi
import plateimpact_plugins
from plateimpact_plugins import report
from plateimpact_plugins.report import presets as report_presets

ROOT = Path(__file__).resolve().parents[1]
CORE = ROOT / "framework" / "plateimpact"

#: Words that are a built-in's name and also plain English where the core uses them.
PLAIN_WORDS = {
    ("model/tables.py", "intact"): "the CF flag meaning of plate_failed = 0 (a state)",
}


def forbidden() -> set[str]:
    """The built-ins' registered names and class names, the report's constant names and
    declarations, the table format's names, the preset names."""
    registry = pi.default_registry()
    names: set[str] = set()
    for kind in ("resistance", "failure", "integrator"):
        for name in registry.names(kind):
            cls = registry.get(kind, name)
            if cls.__module__.startswith("plateimpact_plugins"):
                names |= {name, cls.__name__}
    names |= {n for n in plateimpact_plugins.__all__ if n != "plateimpact_register"}
    # the room's vocabulary (its calibration procedure's function names are not: the core
    # keeps deprecated aliases of them for one release)
    names |= set(report.__all__) - {"failure_plane_depth", *report.CALIBRATION}
    constants = (report.STRENGTH_A, report.DENSITY_B, report.CRITICAL_PENETRATION,
                 report.FAILURE_ANGLE)  # fmt: skip
    names |= {c.name for c in constants if len(c.name) > 1} | {c.key for c in constants}
    # the table's own columns (its obliquity_deg is any angle column's name)
    names |= set(report.TABLE_COLUMNS) - {"obliquity_deg"}
    names |= set(report_presets.PLATES) | {"SAE_52100_DENSITY"}
    return names


def docstring_positions(source: str) -> set[tuple[int, int]]:
    """Start (line, column) of every docstring of a module, class or function."""
    found = set()
    for node in ast.walk(ast.parse(source)):
        if isinstance(node, ast.Module | ast.ClassDef | ast.FunctionDef | ast.AsyncFunctionDef):
            body = node.body
            if body and isinstance(body[0], ast.Expr) and isinstance(body[0].value, ast.Constant):
                if isinstance(body[0].value.value, str):
                    found.add((body[0].lineno, body[0].col_offset))
    return found


def code_words(path: Path) -> list[tuple[int, str]]:
    """(line, word) of every NAME token and every word of a non-docstring string literal."""
    source = path.read_text()
    docstrings = docstring_positions(source)
    words = []
    for token in tokenize.generate_tokens(io.StringIO(source).readline):
        if token.type == tokenize.NAME:
            words.append((token.start[0], token.string))
        elif token.type in (tokenize.STRING, getattr(tokenize, "FSTRING_MIDDLE", -1)):
            if token.start not in docstrings:
                # whole literal, and its words (a preset name, a flag, a column)
                text = token.string
                words += [(token.start[0], w) for w in re.findall(r"[\w./*-]+", text)]
                words.append((token.start[0], text.strip("\"'")))
    return words


def test_the_core_names_no_built_in_plug_in_constant_table_column_or_preset():
    names = forbidden()
    assert {"poncelet", "plugging", "dopri5", "Plugging", "STRENGTH_A", "critical_penetration",
            "pstar_mm", "ricochet_pstar_mm", "2024-T3/3.18", "PstarTable"} <= names  # fmt: skip
    found = []
    for path in sorted(CORE.rglob("*.py")):
        where = str(path.relative_to(CORE))
        found += [
            f"{where}:{line}: {word}"
            for line, word in code_words(path)
            if word in names and (where, word) not in PLAIN_WORDS
        ]
    assert not found, "\n".join(found)


def test_a_docstring_is_prose_but_a_string_literal_is_code(tmp_path):
    path = tmp_path / "m.py"
    path.write_text('"""Uses plugging (eq 8)."""\n\nNAME = "plugging"\n# a comment: poncelet\n')
    assert [w for _, w in code_words(path) if w in forbidden()] == ["plugging", "plugging"]


def test_calibrate_is_the_registered_procedures_and_without_one_is_one_line(capsys):
    from plateimpact.cli import main

    bare = pi.load_registry(entry_points=False)  # no plug-in package: no procedure
    assert main(["calibrate", "shots.csv"], registry=bare) == 2
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and "no installed plug-in package provides the calibrate" in err
    procedure = pi.default_registry().procedure("calibrate")
    assert procedure.__name__ == "plateimpact_plugins.report.calibrate_command"
