"""What goes wrong, and how it is said.

Bad input to the Python API raises a PlateImpactError subclass (a ParameterError is also
a ValueError, an UnknownNameError a LookupError), never a bare TypeError, KeyError or
AttributeError from deep inside. An internal error in the command is one line naming the
file that holds its traceback, exit code 1; ``--debug`` raises it instead.
"""

from __future__ import annotations

import tempfile
import types
from pathlib import Path

import numpy as np
import pytest

import plateimpact as pi
from plateimpact import presets
from plateimpact.cli import main
from plateimpact.cli.commands import plugins as info

SPHERE = presets.DEFAULT_SPHERE
PLATE = presets.plate("2024-T3/3.18")
VARIANT = pi.Variant("report")


def _registry() -> pi.PluginRegistry:
    return pi.default_registry()


BAD_INPUT = {
    "create: unknown kind": (lambda: _registry().create("shape", "poncelet"), pi.UnknownNameError),
    "get: unknown kind": (lambda: _registry().get("shape", "poncelet"), pi.UnknownNameError),
    "names: unknown kind": (lambda: _registry().names("shape"), pi.UnknownNameError),
    "get: a list for a name": (lambda: _registry().get("failure", ["x"]), pi.UnknownNameError),
    "create: a setting too large for a float": (
        lambda: _registry().create("integrator", "dopri5", rtol=10**400),
        pi.ParameterError,
    ),
    "Variant: settings not a mapping": (
        lambda: pi.Variant("v", resistance_settings=[("a", 1)]),
        pi.ParameterError,
    ),
    "Variant: a setting name not a string": (
        lambda: pi.Variant("v", failure_settings={1: 2}),
        pi.ParameterError,
    ),
    "Study: a variant that is not one": (
        lambda: pi.Study.grid("s", ["2024-T3/3.18"], [0], [500], [VARIANT, "other"]),
        pi.ParameterError,
    ),
    "Study: variants as one string": (
        lambda: pi.Study.grid("s", ["2024-T3/3.18"], [0], [500], "report"),
        pi.ParameterError,
    ),
    "Study: no plates": (lambda: pi.Study.grid("s", [], [0], [500], VARIANT), pi.ParameterError),
    "Study: a plate that is neither a name nor a Plate": (
        lambda: pi.Study.grid("s", [3.18], [0], [500], VARIANT),
        pi.ParameterError,
    ),
    "Study: speeds that are not numbers": (
        lambda: pi.Study.grid("s", ["2024-T3/3.18"], [0], ["fast"], VARIANT),
        pi.ParameterError,
    ),
    "Study: scenes that are not a batch": (
        lambda: pi.Study("s", [pi.Scene(SPHERE, PLATE, 500.0, 0.0)], VARIANT, ["p"]),
        pi.ParameterError,
    ),
    "Study: labels that are not a sequence": (
        lambda: pi.Study("s", pi.SceneBatch.grid(SPHERE, PLATE, [500], [0]), VARIANT, 7),
        pi.ParameterError,
    ),
    "Study.from_scenes: not scenes": (
        lambda: pi.Study.from_scenes("s", [PLATE], VARIANT),
        pi.ParameterError,
    ),
    "run_batch: not a batch": (lambda: pi.Simulation.from_names().run_batch(5), pi.ParameterError),
    "run_batch: not scenes": (
        lambda: pi.Simulation.from_names().run_batch([SPHERE, PLATE]),
        pi.ParameterError,
    ),
    "run: not a scene": (lambda: pi.Simulation.from_names().run(PLATE), pi.ParameterError),
    "from_names: settings not a mapping": (
        lambda: pi.Simulation.from_names(integrator_settings=1e-8),
        pi.ParameterError,
    ),
    "from_names: a registry that is not one": (
        lambda: pi.Simulation.from_names(registry={"resistance": {}}),
        pi.ParameterError,
    ),
    "SceneBatch: columns not a mapping": (lambda: pi.SceneBatch([1.0, 2.0]), pi.ParameterError),
    "SceneBatch: a column of text": (
        lambda: pi.SceneBatch({"radius": ["a"], "mass": [1.0]}),
        pi.ParameterError,
    ),
    "SceneBatch: columns of different lengths": (
        lambda: pi.SceneBatch({"radius": [1e-3, 2e-3], "mass": [1e-3]}),
        pi.ParameterError,
    ),
    "SceneBatch.grid: a plate for the sphere": (
        lambda: pi.SceneBatch.grid(PLATE, PLATE, [500], [0]),
        pi.ParameterError,
    ),
    "SceneBatch.concat: not batches": (lambda: pi.SceneBatch.concat([1]), pi.ParameterError),
    "SceneBatch.with_columns: a wrong length": (
        lambda: pi.SceneBatch.grid(SPHERE, PLATE, [500], [0]).with_columns(a=[1.0, 2.0]),
        pi.ParameterError,
    ),
    "load_registry: plugins not iterable": (
        lambda: pi.load_registry(entry_points=False, plugins=5),
        pi.PluginError,
    ),
    "load_registry: a hook with an argument the spec lacks": (
        lambda: pi.load_registry(
            entry_points=False,
            plugins=[types.SimpleNamespace(plateimpact_register=pi.hookimpl(lambda reg: None))],
        ),
        pi.PluginError,
    ),
    "StudyResults: an unknown run": (
        lambda: pi.StudyResults(None, {})["nope"],
        pi.UnknownNameError,
    ),
}


@pytest.mark.parametrize("case", list(BAD_INPUT))
def test_bad_input_raises_a_plateimpact_error(case):
    call, expected = BAD_INPUT[case]
    with pytest.raises(expected) as raised:
        call()
    assert isinstance(raised.value, pi.PlateImpactError)
    natural = {pi.ParameterError: ValueError, pi.UnknownNameError: LookupError}
    assert isinstance(raised.value, natural.get(expected, pi.PlateImpactError))
    assert "\n" not in str(raised.value)  # one line, as the CLI prints it


def test_a_misspelled_hook_handed_to_load_registry_is_both_kinds_of_error():
    import pluggy

    plugin = types.SimpleNamespace(plateimpact_regster=pi.hookimpl(lambda registry: None))
    with pytest.raises(pi.PluginError) as raised:
        pi.load_registry(entry_points=False, plugins=[plugin])
    assert isinstance(raised.value, pluggy.PluginValidationError)
    assert "unknown hook 'plateimpact_regster'" in str(raised.value)


def test_a_good_batch_is_unchanged_by_the_checks():
    batch = pi.SceneBatch.grid(SPHERE, PLATE, [400.0, 500.0], np.radians([0.0, 30.0]))
    again = pi.SceneBatch(batch.columns)
    for name, column in batch.columns.items():
        np.testing.assert_array_equal(again.columns[name], column)
    wider = batch.with_columns(extra=2.0)
    np.testing.assert_array_equal(wider.extra, [2.0] * 4)


def _bug(*args: object) -> None:
    raise RuntimeError("index out of step\nsecond line of the message")


@pytest.fixture
def buggy_plugins_command(monkeypatch, tmp_path):
    """`plateimpact plugins` with a bug in it; tracebacks go under tmp_path."""
    monkeypatch.setattr(info, "run", _bug)
    monkeypatch.setenv("XDG_CACHE_HOME", str(tmp_path))


def test_an_internal_error_is_one_line_naming_the_traceback_file(
    buggy_plugins_command, tmp_path, capsys
):
    assert main(["plugins"]) == 1
    [line] = capsys.readouterr().err.splitlines()
    prefix = "plateimpact: internal error: RuntimeError: index out of step; the traceback is in "
    assert line.startswith(prefix)
    path = Path(line.removeprefix(prefix))
    assert path.parent == tmp_path / "plateimpact"
    text = path.read_text()
    assert "command: plateimpact plugins\n" in text
    assert "Traceback (most recent call last)" in text
    assert "in _bug" in text and "second line of the message" in text


def test_debug_raises_the_internal_error_with_its_traceback(buggy_plugins_command, tmp_path):
    with pytest.raises(RuntimeError, match="index out of step"):
        main(["--debug", "plugins"])
    assert not (tmp_path / "plateimpact").exists()


def test_a_traceback_that_cannot_be_written_is_said_on_the_same_line(
    buggy_plugins_command, tmp_path, monkeypatch, capsys
):
    blocker = tmp_path / "a-file"
    blocker.write_text("")
    monkeypatch.setenv("XDG_CACHE_HOME", str(blocker))  # no directory can be made in a file
    monkeypatch.setattr(tempfile, "tempdir", str(blocker / "tmp"))
    assert main(["plugins"]) == 1
    [line] = capsys.readouterr().err.splitlines()
    assert line.startswith(
        "plateimpact: internal error: RuntimeError: index out of step; "
        "the traceback could not be written ("
    )
    assert line.endswith("); run with --debug to see it")


def test_an_interrupt_is_one_line_and_exit_code_130(monkeypatch, capsys):
    def interrupted(*args: object) -> None:
        raise KeyboardInterrupt

    monkeypatch.setattr(info, "run", interrupted)
    assert main(["plugins"]) == 130
    assert capsys.readouterr().err == "plateimpact: interrupted\n"
