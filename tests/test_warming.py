"""No run waits for numba: under engine="auto" a pair whose compiled program is not ready runs
on the numpy path and one detached process compiles it; a ready program runs compiled; a
failed one runs on the numpy path with its reason in one warning line; the program's lock
keeps a second compile from starting; and the warm-up compiles exactly the signature a
batch runs. Each state is made directly (markers, a held lock, a recorded Popen): no test
waits for a process or a compile."""

from __future__ import annotations

import json
import os
import subprocess
import sys
import warnings

import pytest

import plateimpact as pi
from plateimpact.cli import main
from plateimpact.solve.compiled import building, cache, program, warming
from plateimpact.solve.driver import _cold, _warned, choose_engine
from plateimpact_plugins.plugging import Plugging
from plateimpact_plugins.poncelet import Poncelet

pytest.importorskip("numba")


@pytest.fixture
def cold_cache(tmp_path, monkeypatch):
    """An empty cache directory, and every Popen recorded instead of started."""
    monkeypatch.setenv("PLATEIMPACT_CACHE_DIR", str(tmp_path))
    monkeypatch.delenv("PLATEIMPACT_COMPILE", raising=False)
    started: list[list[str]] = []
    monkeypatch.setattr(
        warming.subprocess, "Popen", lambda command, **kwargs: started.append(command)
    )
    _warned.clear()
    _cold.clear()
    yield started
    _cold.clear()


def _model():
    simulation = pi.Simulation.from_names(failure="plugging")
    return simulation.model, simulation.integrator


def test_a_cold_program_runs_numpy_and_starts_one_compile(cold_cache):
    model, integrator = _model()
    with warnings.catch_warnings():
        warnings.simplefilter("error")  # compiling in the background is not a warning
        assert choose_engine("auto", model, integrator, 10) == "numpy"
    assert len(cold_cache) == 1
    command = cold_cache[0]
    assert command[:3] == [sys.executable, "-m", "plateimpact.solve.compiled.warming"]
    assert command[3:5] == [
        "plateimpact_plugins.poncelet:Poncelet",
        "plateimpact_plugins.plugging:Plugging",
    ]
    assert len(command) == 6 and command[5].isdigit()  # the pipe it waits on


def test_a_program_being_compiled_is_not_started_again(cold_cache):
    key = program.spec(Poncelet, Plugging).key
    with cache.compile_lock(key):  # another process compiling it
        assert warming.start(Poncelet, Plugging) is False
    assert cold_cache == []
    assert warming.start(Poncelet, Plugging) is True  # the lock released
    assert len(cold_cache) == 1


def test_a_process_keeps_the_numpy_path_for_a_pair_it_found_cold(cold_cache):
    """One command's results never change path half-way when the compile finishes."""
    model, integrator = _model()
    assert choose_engine("auto", model, integrator, 10) == "numpy"
    cache.mark(program.spec(Poncelet, Plugging).key)  # the detached compile finished
    assert choose_engine("auto", model, integrator, 10) == "numpy"
    assert choose_engine("compiled", model, integrator, 10) == "compiled"
    assert len(cold_cache) == 1


def test_a_ready_program_runs_compiled(cold_cache):
    model, integrator = _model()
    cache.mark(program.spec(Poncelet, Plugging).key)
    assert choose_engine("auto", model, integrator, 10) == "compiled"
    assert cold_cache == []


def test_a_failed_program_runs_numpy_with_its_reason_once(cold_cache):
    model, integrator = _model()
    key = program.spec(Poncelet, Plugging).key
    cache.mark(key, "compiling failed (TypingError: a kernel numba cannot type)\nmore")
    with pytest.warns(pi.CompiledPathWarning, match="TypingError: a kernel numba") as said:
        assert choose_engine("auto", model, integrator, 10) == "numpy"
        assert choose_engine("auto", model, integrator, 10) == "numpy"
    assert len(said) == 1 and "\n" not in str(said[0].message)
    assert cold_cache == []  # a failure is not retried on every run
    cache.mark(key)  # compiled since (e.g. by plateimpact compile): the next process
    _cold.clear()
    assert choose_engine("auto", model, integrator, 10) == "compiled"


def test_compiling_can_be_switched_off(cold_cache, monkeypatch):
    monkeypatch.setenv("PLATEIMPACT_COMPILE", "off")
    model, integrator = _model()
    assert choose_engine("auto", model, integrator, 10) == "numpy"
    assert cold_cache == []


def test_the_detached_process_waits_for_its_starter_to_end(tmp_path, monkeypatch):
    """It compiles once the pipe's write end (held by the starter) is closed: here the
    pipe is closed before, and the compile is recorded instead of run."""
    monkeypatch.setenv("PLATEIMPACT_CACHE_DIR", str(tmp_path))
    monkeypatch.setattr(warming.os, "nice", lambda increment: 0)
    compiled = []
    monkeypatch.setattr(
        warming, "compile_pairs", lambda pairs: compiled.append(pairs) or [("", "ready")]
    )
    waited, held = os.pipe()
    os.write(held, b"x")  # bytes before the end are read and ignored
    os.close(held)
    names = ["plateimpact_plugins.poncelet:Poncelet", "plateimpact_plugins.plugging:Plugging"]
    assert warming.main([*names, str(waited)]) == 0
    os.close(waited)
    assert compiled == [[(Poncelet, Plugging)]]


def test_the_detached_process_refuses_bad_arguments():
    assert warming.main(["plateimpact_plugins.poncelet:Poncelet"]) == 2
    assert warming.main(["no.such.module:Law", "plateimpact_plugins.plugging:Plugging"]) == 2
    # a class of the wrong kind
    assert warming.main(["plateimpact_plugins.plugging:Plugging"] * 2) == 2


def test_the_warm_up_compiles_the_signature_a_batch_runs():
    """A batch run after the warm-up (the suite's, in conftest) adds no compiled
    specialisation: signature_arguments has the types integrate_compiled passes."""
    simulation = pi.Simulation.from_names(failure="plugging", engine="compiled")
    batch = pi.SceneBatch.grid(
        pi.presets.DEFAULT_SPHERE, pi.presets.plate("2024-T3/3.18"), [300.0, 900.0], [0.0, 1.0]
    )
    result = simulation.run_batch(batch, record_trajectory=True)
    assert result.stats["compiled_scenes"] == 4
    compiled = building.build(Poncelet, Plugging)
    assert len(compiled.run.signatures) == 1


def test_compile_command_reports_every_installed_pair(capsys):
    assert main(["compile", "--json"]) == 0
    said = json.loads(capsys.readouterr().out)
    assert said["pairs"] == {
        f"poncelet + {failure}": "ready"
        for failure in ("hinge", "intact", "plugging", "variable-pstar")
    }


def test_the_module_runs_as_a_program():
    """The command the background start runs exists (bad arguments: exit 2, at once)."""
    done = subprocess.run(
        [sys.executable, "-m", "plateimpact.solve.compiled.warming", "x:Y", "x:Z"],
        capture_output=True,
        timeout=120,
    )
    assert done.returncode == 2
