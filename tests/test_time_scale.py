"""The suite's clock-free promise, and the harness that checks it: with
PLATEIMPACT_TEST_TIME_SCALE every wall-clock limit the package has by default is scaled,
in this process and in every Python process the tests start (tests/time_scale)."""

from __future__ import annotations

import json
import math
import os
import subprocess
import sys

from conftest import SCALE, TIME_SCALE

import plateimpact as pi
from plateimpact.provenance import metadata as provenance
from plateimpact.run import progress
from plateimpact.storage import archive

SHOW = (
    "import json, plateimpact as pi; from plateimpact.run import progress;"
    "from plateimpact.storage import archive;"
    "from plateimpact.provenance import metadata as provenance;"
    "print(json.dumps([pi.Archive('a.h5').wait, progress.DELAY, provenance.GIT_TIMEOUT,"
    " pi.MAX_SECONDS.default, pi.Integrator.max_seconds]))"
)


def test_a_process_the_tests_start_scales_every_limit_as_its_modules_load(tmp_path):
    here = [pi.Archive(tmp_path / "a.h5").wait, progress.DELAY, provenance.GIT_TIMEOUT]
    defaults = [value / SCALE for value in here]  # this process is scaled by SCALE
    assert defaults == [archive.WAIT / SCALE, 2.0, 60.0] and math.isclose(defaults[0], 300.0)
    environment = {**os.environ, "PLATEIMPACT_TEST_TIME_SCALE": "0.25",
                   "PYTHONPATH": str(TIME_SCALE)}  # fmt: skip
    done = subprocess.run([sys.executable, "-c", SHOW], capture_output=True, text=True,
                          env=environment, cwd=tmp_path, check=True)  # fmt: skip
    wait, delay, git, *max_seconds = json.loads(done.stdout)
    assert [wait, delay, git] == [0.25 * value for value in defaults]
    assert max_seconds == [None, None]  # no wall-time bound by default: nothing to scale
