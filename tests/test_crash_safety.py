"""Crash safety (issue 7): a study killed (SIGKILL) at random moments leaves an archive
that opens, with every finished run intact and the interrupted one absent, and
``study.run(resume=True)`` completes it. Three kills in CI; 20 with
HYPOTHESIS_PROFILE=stress."""

from __future__ import annotations

import os
import random
import signal
import subprocess
import sys
import textwrap
import time

import numpy as np
import pytest

import plateimpact as pi

SCRIPT = """
import sys
import numpy as np
import plateimpact as pi
sys.path.insert(0, {tests!r})
from test_crash_safety import study
study().run(archive=sys.argv[1], chunk_size=40)
"""


def study() -> pi.Study:
    """Three variants of a few seconds each: kills land before, during and between runs."""
    variants = [
        pi.Variant("fast"),
        pi.Variant("coarse", integrator_settings={"rtol": 1e-6}),
        pi.Variant("segment", integrator="segment", integrator_settings={"step": 1e-3}),
    ]
    speeds = np.linspace(150.0, 1200.0, 30)
    return pi.Study.grid("crash", ["2024-T3/3.18", "SAE1010/1.47"], [0, 45], speeds, variants)


KILLS = 20 if os.environ.get("HYPOTHESIS_PROFILE") == "stress" else 3


@pytest.fixture(scope="module")
def expected() -> pi.StudyResults:
    return study().run()


def test_random_kills_never_lose_a_finished_run_and_resume_completes(tmp_path, expected):
    script = tmp_path / "writer.py"
    script.write_text(textwrap.dedent(SCRIPT.format(tests=os.path.dirname(__file__))))
    start = time.perf_counter()
    subprocess.run([sys.executable, str(script), str(tmp_path / "timing.h5")], check=True)
    full = time.perf_counter() - start
    rng = random.Random(5844)
    for k in range(KILLS):
        path = tmp_path / f"a{k}.h5"
        child = subprocess.Popen([sys.executable, str(script), str(path)])
        time.sleep(rng.uniform(0.0, full))
        child.send_signal(signal.SIGKILL)
        child.wait()
        if path.exists():  # killed after the first run was written
            archive = pi.Archive(path)
            finished = archive.runs()
            assert finished == [f"crash/{v.name}" for v in study().variants][: len(finished)]
            for run in finished:
                result = archive.results(run)
                np.testing.assert_array_equal(result.exit_speed, expected[run[6:]].exit_speed)
        resumed = study().run(archive=path, resume=True)
        for variant in study().variants:
            np.testing.assert_array_equal(
                resumed[variant.name].exit_speed, expected[variant.name].exit_speed
            )
        assert pi.Archive(path).runs() == [f"crash/{v.name}" for v in study().variants]
        # The killed writer's temporary copy is gone once the archive is written again.
        assert not [p.name for p in tmp_path.iterdir() if p.name.startswith(f".a{k}.h5")]
