"""The compiled path against the numpy path: the same outcomes and results, scene by
scene, for every built-in failure model (issue 23, item 2), the engine choice, and the
fallback where numba is missing.

The paths share every formula and take the same steps, so they differ only by rounding.
numpy's vectorised arccos, arctan2 and pow (its AVX-512 builds) differ from the C
library's, which numba calls, in the last bit; a last-bit difference can move a branch
landing and so a result by up to the integration tolerance. The 1e-12 comparison
therefore runs the numpy path in a process whose numpy uses its baseline code
(``NPY_DISABLE_CPU_FEATURES``: the C library's functions, as numba); a second test
bounds what the default numpy's last bits do.
"""

from __future__ import annotations

import os
import subprocess
import sys
import warnings
from pathlib import Path

import attrs
import numpy as np
import pytest

import plateimpact as pi
from plateimpact.registry import presets

numba = pytest.importorskip("numba")

FAILURES = ("plugging", "hinge", "variable-pstar", "intact")
SCENES = 2_000


def batch(size: int = SCENES, seed: int = 23) -> pi.SceneBatch:
    """Scenes over every preset: obliquity 0–80°, impact speed 50–1500 m/s."""
    rng = np.random.default_rng(seed)
    parts = []
    names = list(presets.PLATES)
    for k, name in enumerate(names):
        count = size // len(names) + (1 if k < size % len(names) else 0)
        part = pi.SceneBatch.grid(presets.DEFAULT_SPHERE, presets.plate(name), [100.0], [0.0])
        part = pi.SceneBatch.concat([part] * count)
        parts.append(
            part.with_columns(
                impact_speed=rng.uniform(50.0, 1500.0, count),
                impact_obliquity=np.radians(rng.uniform(0.0, 80.0, count)),
            )
        )
    return pi.SceneBatch.concat(parts)


def run(failure: str, engine: str, scenes: pi.SceneBatch | None = None) -> pi.BatchResult:
    simulation = pi.Simulation.from_names(failure=failure, engine=engine)
    return simulation.run_batch(batch() if scenes is None else scenes)


def _baseline_numpy_results(tmp_path: Path) -> dict[str, np.ndarray]:
    """The numpy path's results in a process whose numpy runs its baseline code."""
    from numpy._core._multiarray_umath import (  # noqa: PLC0415
        __cpu_baseline__,
        __cpu_dispatch__,
        __cpu_features__,
    )

    dispatched = [f for f in __cpu_dispatch__ if __cpu_features__.get(f)]
    disable = " ".join(f for f in dispatched if f not in __cpu_baseline__)
    out = tmp_path / "numpy.npz"
    script = (
        "import sys, numpy as np\n"
        f"sys.path.insert(0, {str(Path(__file__).parent)!r})\n"
        "from test_compiled import FAILURES, run\n"
        "from plateimpact.solve.compiled.elementary import in_numpy_path\n"
        "in_numpy_path()\n"
        "found = {}\n"
        "for failure in FAILURES:\n"
        "    r = run(failure, 'numpy')\n"
        "    for name in ('outcome', 'plate_failed', 'exit_speed', 'exit_obliquity',"
        " 'contact_time', 'max_penetration', 'failure_time', 'failure_penetration'):\n"
        "        found[failure + '/' + name] = r.columns[name]\n"
        "    for name, value in r.stats.items():\n"
        "        found[failure + '/stats/' + name] = np.array(value)\n"
        f"np.savez({str(out)!r}, **found)\n"
    )
    env = {**os.environ, "NPY_DISABLE_CPU_FEATURES": disable}
    subprocess.run([sys.executable, "-c", script], check=True, env=env, timeout=600)
    with np.load(out) as saved:
        return dict(saved)


@pytest.fixture(scope="module")
def baseline(tmp_path_factory):
    return _baseline_numpy_results(tmp_path_factory.mktemp("compiled"))


@pytest.mark.parametrize("failure", FAILURES)
def test_compiled_path_takes_the_numpy_paths_steps(failure, baseline):
    """Same outcome, failure and work per scene; exit speed within 1e-12 Vs, exit
    obliquity within 1e-9°, times and depths to rounding, on 2,000 scenes over every
    preset: the same algorithm, step for step, with the same elementary functions (the
    compiled path's, in the numpy path too) and the same C library for the rest."""
    scenes = batch()
    compiled = run(failure, "compiled", scenes)
    assert compiled.stats["compiled_scenes"] == scenes.size
    expected = {k.split("/", 1)[1]: v for k, v in baseline.items() if k.startswith(failure + "/")}
    c = compiled.columns
    np.testing.assert_array_equal(c["outcome"], expected["outcome"])
    np.testing.assert_array_equal(c["plate_failed"], expected["plate_failed"])
    speed = scenes.columns["impact_speed"]
    assert np.max(np.abs(c["exit_speed"] - expected["exit_speed"]) / speed) <= 1e-12
    difference = np.abs(c["exit_obliquity"] - expected["exit_obliquity"])
    assert np.degrees(np.max(difference)) <= 1e-9
    radius = scenes.columns["radius"]
    for name in ("max_penetration", "failure_penetration"):
        np.testing.assert_array_equal(np.isnan(c[name]), np.isnan(expected[name]))
        assert np.nanmax(np.abs(c[name] - expected[name]) / radius, initial=0.0) <= 1e-12
    for name in ("contact_time", "failure_time"):
        np.testing.assert_array_equal(np.isnan(c[name]), np.isnan(expected[name]))
        scale = radius / speed  # Rs/Vs
        assert np.nanmax(np.abs(c[name] - expected[name]) / scale, initial=0.0) <= 1e-10
    for name in ("accepted_steps", "rejected_steps", "force_evaluations", "steps"):
        assert compiled.stats[name] == int(expected["stats/" + name]), name


@pytest.mark.parametrize("failure", FAILURES)
def test_compiled_path_agrees_with_the_default_numpy(failure):
    """With numpy's own vectorised math (last bits apart from the C library's), the
    outcomes are the same and the exit speed and obliquity agree within what the
    integration tolerance promises (2e-7 Vs, 1e-5°, docs/integrators.md)."""
    scenes = batch(1_000, seed=5)
    compiled, numpy_path = run(failure, "compiled", scenes), run(failure, "numpy", scenes)
    np.testing.assert_array_equal(compiled.outcome, numpy_path.outcome)
    speed = scenes.columns["impact_speed"]
    assert np.max(np.abs(compiled.exit_speed - numpy_path.exit_speed) / speed) <= 2e-7
    angle = np.abs(compiled.columns["exit_obliquity"] - numpy_path.columns["exit_obliquity"])
    assert np.degrees(np.max(angle)) <= 1e-5


def test_lanes_give_what_one_scene_at_a_time_gives_bit_for_bit(monkeypatch):
    """The compiled path steps 64 scenes together (solve/compiled/lanes.py), each lane
    doing the one-at-a-time driver's operations in its order: every result and count
    equal bit for bit, trajectories included, on the hinge (failure state, four branch
    rows, the finger) over every preset, with plates failing, the ring and all five
    outcomes among the scenes; and in reverse order (other neighbours in each lane)."""
    from plateimpact.solve.compiled import building  # noqa: PLC0415

    simulation = pi.Simulation.from_names(failure="hinge", engine="compiled")
    scenes = batch(600, seed=11)
    lanes = simulation.run_batch(scenes, record_trajectory=True)
    assert len(set(lanes.outcome.tolist())) >= 3 and lanes.columns["plate_failed"].any()
    reverse = np.arange(scenes.size)[::-1]
    backwards = simulation.run_batch(scenes.take(reverse))
    program = building.build(type(simulation.model.resistance), type(simulation.model.failure))
    monkeypatch.setattr(program, "run", program.run_one_at_a_time)
    alone = simulation.run_batch(scenes, record_trajectory=True)
    assert lanes.stats == alone.stats
    for name, column in lanes.columns.items():
        np.testing.assert_array_equal(column, alone.columns[name], err_msg=name)
        np.testing.assert_array_equal(column[reverse], backwards.columns[name], err_msg=name)
    for i in (0, 299, 599):
        a, b = lanes.trajectory_of(i), alone.trajectory_of(i)
        for name in ("time", "penetration", "lateral", "obliquity", "speed"):
            np.testing.assert_array_equal(getattr(a, name), getattr(b, name), err_msg=name)


@pytest.mark.parametrize("column", [1, -2, 0.0])
def test_a_relief_plane_outside_the_kernel_constants_is_one_plugin_error(column):
    """Compiled code reads a declared relief plane's row unchecked, so a plug-in whose
    ``relief_column`` is not a row of its kernel constants (plugging has one row) is
    refused before any scene runs, in one line naming the field and the range."""
    from plateimpact_plugins.plugging import Plugging  # noqa: PLC0415

    kernels = Plugging.kernels._replace(relief_column=column)
    broken = type("BrokenRelief", (Plugging,), {"kernels": kernels, "name": "broken-relief"})
    simulation = pi.Simulation.from_names(failure="plugging", engine="compiled")
    simulation = attrs.evolve(simulation, model=attrs.evolve(simulation.model, failure=broken()))
    with pytest.raises(pi.PluginError, match=r"relief_column=.* \(0 to 0, or -1"):
        simulation.run_batch(batch(12))


def test_auto_runs_compiled_whatever_the_size_and_chunking_changes_nothing():
    """The engine never depends on a run's size, so a scene's result is the same alone,
    in a batch and in chunks, bit for bit."""
    simulation = pi.Simulation.from_names(failure="plugging")
    scenes = batch(300)
    whole = simulation.run_batch(scenes)
    assert whole.stats["compiled_scenes"] == scenes.size
    chunked = simulation.run_batch(scenes, chunk_size=7)
    np.testing.assert_array_equal(chunked.exit_speed, whole.exit_speed)
    alone = simulation.run_batch(scenes.take(np.array([17])))
    assert alone.exit_speed[0] == whole.exit_speed[17]


@pytest.mark.parametrize("n", [1, 63, 64, 129, 1000, 10_007])
@pytest.mark.parametrize("threads", [1, 2, 3])
def test_strided_chunks_cover_every_scene_once(n, threads, monkeypatch):
    """The threads' chunks (every C-th scene from each first scene) hand out each scene
    exactly once, whatever the batch's size and the thread count."""
    from plateimpact.solve.compiled import engine  # noqa: PLC0415

    monkeypatch.setattr(engine, "_threads", [threads])
    handed: list[int] = []
    engine.run_parallel(lambda start, stop, step: handed.extend(range(start, stop, step)), n, ())
    assert sorted(handed) == list(range(n))


def test_one_thread_and_two_give_the_same_results_bit_for_bit(monkeypatch):
    """Two threads take strided chunks of the batch (other neighbours in each lane, other
    order): every result, count and trajectory equals one thread's, bit for bit."""
    from plateimpact.solve.compiled import engine  # noqa: PLC0415

    simulation = pi.Simulation.from_names(failure="plugging", engine="compiled")
    scenes = batch(600, seed=12)
    monkeypatch.setattr(engine, "_threads", [1])
    one = simulation.run_batch(scenes, record_trajectory=True)
    monkeypatch.setattr(engine, "_threads", [2])
    two = simulation.run_batch(scenes, record_trajectory=True)
    assert one.stats == two.stats
    for name, column in one.columns.items():
        np.testing.assert_array_equal(column, two.columns[name], err_msg=name)
    for i in (0, 301, 599):
        a, b = one.trajectory_of(i), two.trajectory_of(i)
        for name in ("time", "penetration", "lateral", "obliquity", "speed"):
            np.testing.assert_array_equal(getattr(a, name), getattr(b, name), err_msg=name)


def test_numpy_only_settings_stay_on_the_numpy_path():
    # Any fixed step is numpy-only; a coarse one (0.1 Rs/Vs) keeps the run short.
    fixed = pi.Simulation.from_names(
        failure="plugging", integrator_settings={"fixed_step": 0.1}, engine="auto"
    )
    assert fixed.run_batch(batch(20)).stats["compiled_scenes"] == 0
    with pytest.raises(pi.ParameterError, match="engine 'compiled' cannot run"):
        pi.Simulation.from_names(
            failure="plugging", integrator_settings={"fixed_step": 0.1}, engine="compiled"
        ).run_batch(batch(5))


def test_without_numba_the_numpy_path_runs_with_one_warning_line(monkeypatch):
    """numba made unimportable (deterministically, in this process): the run completes
    on the numpy path, and says so in one warning, once."""
    from plateimpact.solve import driver  # noqa: PLC0415

    monkeypatch.setitem(sys.modules, "numba", None)  # import numba -> ImportError
    monkeypatch.setattr(driver, "_warned", set())
    simulation = pi.Simulation.from_names(failure="plugging")
    scenes = batch(20)
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        first = simulation.run_batch(scenes)
        simulation.run_batch(scenes)
    said = [w for w in caught if issubclass(w.category, pi.CompiledPathWarning)]
    assert len(said) == 1 and "\n" not in str(said[0].message)
    assert "numba is not installed" in str(said[0].message)
    assert first.stats["compiled_scenes"] == 0 and np.all(first.outcome > 0)


def test_engine_is_validated():
    with pytest.raises(pi.ParameterError, match="engine must be one of auto, compiled, numpy"):
        pi.Simulation.from_names(engine="fast")
