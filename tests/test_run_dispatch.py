"""The run path once (simulation.run_in_chunks): :meth:`Simulation.run_batch` and
:meth:`Study.run` dispatch through the same code, bind each model once per run, and a
scene's result does not depend on the chunk it ran in or on the process that ran it."""

from __future__ import annotations

from concurrent.futures import ProcessPoolExecutor

import numpy as np
import pytest

import plateimpact as pi
from plateimpact import presets
from plateimpact.model.impact import ImpactModel

SPEEDS = np.linspace(150.0, 1200.0, 7)
VARIANTS = [pi.Variant("plugging"), pi.Variant("hinge", failure="hinge")]


def study() -> pi.Study:
    return pi.Study.grid(
        "dispatch", ["2024-T3/3.18", "SAE1010/1.47"], [0, 45, 70], SPEEDS, VARIANTS
    )


@pytest.fixture
def binds(monkeypatch):
    """How many scenes each call of ImpactModel.bind bound."""
    sizes: list[int] = []
    real = ImpactModel.bind

    def counted(model, batch):
        sizes.append(batch.size)
        return real(model, batch)

    monkeypatch.setattr(ImpactModel, "bind", counted)
    return sizes


def test_a_study_binds_each_model_once_and_runs_it_in_chunks(binds, chunks):
    s = study()
    s.run(chunk_size=10)
    assert binds == [s.scenes.size] * len(VARIANTS)  # once per run, the whole study
    per_run = [10, 10, 10, 10, 2]  # 42 scenes
    assert chunks == per_run * len(VARIANTS)


def test_a_batch_in_one_process_is_one_chunk_bound_once(binds, chunks):
    scenes = study().scenes
    pi.Simulation.from_names().run_batch(scenes, chunk_size=10)
    assert binds == [scenes.size] and chunks == [scenes.size]


def test_a_study_gives_each_scene_the_result_of_the_simulation_alone():
    """Chunks of 5 scenes, a study's bookkeeping, or the whole batch at once: the same
    results, bit for bit (each scene is integrated by itself: its steps do not depend on
    the other scenes of its batch)."""
    s = study()
    runs = s.run(chunk_size=5, record_trajectory=True)
    for variant in VARIANTS:
        alone = variant.simulation().run_batch(s.scenes, record_trajectory=True)
        for name, column in alone.columns.items():
            np.testing.assert_array_equal(runs[variant.name].columns[name], column, err_msg=name)
        stored, direct = runs[variant.name].trajectory, alone.trajectory
        assert stored is not None and direct is not None
        np.testing.assert_array_equal(stored.offsets, direct.offsets)


def test_a_study_on_a_process_pool_gives_the_same_results_as_in_process():
    s = pi.Study.grid("pool", ["2024-T3/3.18"], [30], SPEEDS, VARIANTS[0])
    here = s.run(chunk_size=3)
    with ProcessPoolExecutor(2) as pool:
        there = s.run(chunk_size=3, executor=pool)
    for name, column in here["plugging"].columns.items():
        np.testing.assert_array_equal(there["plugging"].columns[name], column, err_msg=name)


def test_a_bad_plate_constant_of_any_variant_is_refused_before_any_chunk_runs(chunks):
    plate = presets.plate("2024-T3/3.18").with_constants(critical_penetration=-1.0)
    s = pi.Study.from_scenes("bad", [pi.Scene(presets.DEFAULT_SPHERE, plate, 500.0, 0.5)], VARIANTS)
    with pytest.raises(pi.ParameterError):
        s.run()
    assert chunks == []
