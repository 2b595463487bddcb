"""Crash safety (issue 7): a study killed (SIGKILL) anywhere leaves an archive that
opens, with every finished run intact and the interrupted one absent, and
``study.run(resume=True)`` completes it.

The kills are deterministic, never timed: the writer, a child forked from the test's
process, kills itself on entering a chunk of scenes (before, during and between runs) or
at a named stage of a run's append (``storage.append.fault_point``), so what a test sees
never depends on how fast or busy the machine is. Four kill points in CI; every one with
HYPOTHESIS_PROFILE=stress."""

from __future__ import annotations

import os
import signal
from pathlib import Path

import numpy as np
import pytest
from forking import forked
from test_archive_writers import debris

import plateimpact as pi
import plateimpact.run.simulation
from plateimpact.storage import append

#: Scenes per chunk: each run is two chunks.
CHUNK = 20
#: The stages of an append, in order ("unlock": the run is in, the lock still held).
STAGES = ("copy", "write", "flush", "fsync", "replace", "unlock")


def study() -> pi.Study:
    """Three cheap variants (the kills are placed, not timed, so no run need be slow)."""
    variants = [
        pi.Variant("fast"),
        pi.Variant("coarse", integrator_settings={"rtol": 1e-6}),
        pi.Variant("segment", integrator="segment", integrator_settings={"step": 1e-2}),
    ]
    speeds = np.linspace(150.0, 1200.0, 10)
    return pi.Study.grid("crash", ["2024-T3/3.18", "SAE1010/1.47"], [0, 45], speeds, variants)


RUNS = [f"crash/{v.name}" for v in study().variants]
#: Where the writer dies: on entering chunk N (1, 2: the first run; 3: between the first
#: and second; 6: in the third), or at a stage of the Nth run's append.
EVERY_KILL = [("chunk", str(n)) for n in range(1, 2 * len(RUNS) + 1)] + [
    ("append", str(run), stage) for run in range(1, len(RUNS) + 1) for stage in STAGES
]
CI_KILLS = [("chunk", "2"), ("append", "1", "flush"), ("chunk", "5"), ("append", "3", "unlock")]
KILLS = EVERY_KILL if os.environ.get("HYPOTHESIS_PROFILE") == "stress" else CI_KILLS


def killed_writer(path: Path, kill: tuple[str, ...]) -> int:
    """The returncode of a writer (forked from this process) that runs :func:`study` into
    ``path`` and SIGKILLs itself at ``kill``."""
    kind, where = kill[0], kill[1:]
    chunks, appends = [0], [0]
    run_chunk = plateimpact.run.simulation.run_chunk

    def die() -> None:
        os.kill(os.getpid(), signal.SIGKILL)

    def counted_chunk(*args, **kwargs):
        chunks[0] += 1
        if kind == "chunk" and chunks[0] == int(where[0]):
            die()
        return run_chunk(*args, **kwargs)

    def fault_point(stage: str) -> None:
        if stage == "copy":
            appends[0] += 1
        if kind == "append" and appends[0] == int(where[0]) and stage == where[1]:
            die()

    def write() -> None:  # in the child: this process's modules are untouched
        plateimpact.run.simulation.run_chunk = counted_chunk
        append.fault_point = fault_point
        study().run(archive=path, chunk_size=CHUNK)

    return forked(write).returncode


def finished_before(kill: tuple[str, ...]) -> int:
    """The runs a writer killed at ``kill`` has finished (its append is in)."""
    if kill[0] == "chunk":
        return (int(kill[1]) - 1) // 2
    return int(kill[1]) - (kill[2] != "unlock")  # at "unlock" the run is already in


@pytest.fixture(scope="module")
def expected() -> pi.StudyResults:
    return study().run()


@pytest.mark.parametrize("kill", KILLS, ids="-".join)
def test_a_kill_anywhere_never_loses_a_finished_run_and_resume_completes(tmp_path, expected, kill):
    path = tmp_path / "a.h5"
    assert killed_writer(path, kill) == -signal.SIGKILL
    finished = finished_before(kill)
    if finished:
        archive = pi.Archive(path)
        assert archive.runs() == RUNS[:finished]
        for run in RUNS[:finished]:
            stored = archive.results(run)
            np.testing.assert_array_equal(stored.exit_speed, expected[run[6:]].exit_speed)
    else:  # killed before its first run was in: the archive is never half made
        assert not path.exists() or pi.Archive(path).runs() == []
    resumed = study().run(archive=path, resume=True)
    for variant in study().variants:
        np.testing.assert_array_equal(
            resumed[variant.name].exit_speed, expected[variant.name].exit_speed
        )
    assert pi.Archive(path).runs() == RUNS
    # The killed writer's temporary copy and the data file no index names are gone once
    # the archive is written again.
    assert debris(tmp_path) == []
