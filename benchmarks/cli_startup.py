"""Start-up time of the ``plateimpact`` command: ``--version``, ``--help`` and one ``run``,
each the median (and minimum) of N runs in a fresh process (subprocess), wall time.

The command lists its commands from a table and imports only the one invoked
(plateimpact.cli), so ``--version`` and ``--help`` import no numeric library and ``run``
no scipy, h5py, matplotlib or xarray. Targets (issue 22): --version and --help under
0.3 s, the run under 1 s, on a 2-core machine. Timings are never asserted in tests.

Run:  python benchmarks/cli_startup.py [--runs 11]
"""

from __future__ import annotations

import argparse
import os
import platform
import shutil
import statistics
import subprocess
import sys
import time

CASES = {
    "--version": ["--version"],
    "--help": ["--help"],
    "run": ["run", "--preset", "2024-T3/3.18", "--speed", "640", "--obliquity", "60"],
}


def command() -> list[str]:
    """The installed console script, else ``python -m plateimpact.cli``."""
    found = shutil.which("plateimpact")
    return [found] if found else [sys.executable, "-m", "plateimpact.cli"]


def timings(argv: list[str], runs: int) -> list[float]:
    found = []
    for _ in range(runs + 1):  # the first warms the file cache
        start = time.perf_counter()
        subprocess.run([*command(), *argv], check=True, capture_output=True)
        found.append(time.perf_counter() - start)
    return found[1:]


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--runs", type=int, default=11, help="runs per case (default 11)")
    runs = parser.parse_args().runs
    print(
        f"{platform.node()}: {os.cpu_count()} cores, python {platform.python_version()}, "
        f"{' '.join(command())}"
    )
    for name, argv in CASES.items():
        found = timings(argv, runs)
        print(
            f"  {name:10s} median {statistics.median(found):.3f} s, min {min(found):.3f} s "
            f"({runs} runs)"
        )


if __name__ == "__main__":
    main()
