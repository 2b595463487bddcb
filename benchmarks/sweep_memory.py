"""Peak memory and wall time of a large ``plateimpact sweep`` (issue 17: a million scenes
in under 500 MB).

python benchmarks/sweep_memory.py [--speeds 10000] [--obliquities 100] [--csv FILE]

Runs, in a child process, the command

    plateimpact sweep --preset 2024-T3/3.18 --speeds 50:1500:SPEEDS
                      --obliquities 0,0.9,...  (OBLIQUITIES values, 0.9 deg apart)
                      --csv FILE --force

(default: 10,000 x 100 = 10^6 scenes, dopri5, one process) and prints its wall time,
its CPU time and its peak resident set size (the child's ru_maxrss, as ``/usr/bin/time
-v`` reports it), and the size of the CSV. The grid is streamed a chunk at a time, so
the peak should not grow with the number of scenes; compare --speeds 1000 with 10000.
"""

from __future__ import annotations

import argparse
import os
import resource
import subprocess
import sys
import tempfile
import time
from pathlib import Path


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--speeds", type=int, default=10_000, help="speeds, 50-1500 m/s")
    parser.add_argument("--obliquities", type=int, default=100, help="obliquities, 0.9 deg apart")
    parser.add_argument("--csv", help="where the sweep writes (default: a temporary file)")
    args = parser.parse_args()
    if not 1 <= args.obliquities <= 100:
        parser.error("--obliquities must be in [1, 100] (0.9 deg apart, below 90 deg)")
    obliquities = ",".join(f"{0.9 * k:g}" for k in range(args.obliquities))
    with tempfile.TemporaryDirectory() as scratch:
        target = Path(args.csv or Path(scratch) / "sweep.csv")
        command = [sys.executable, "-m", "plateimpact.cli", "sweep", "--preset", "2024-T3/3.18",
                   "--speeds", f"50:1500:{args.speeds}", "--obliquities", obliquities,
                   "--csv", str(target), "--force"]  # fmt: skip
        began = time.perf_counter()
        done = subprocess.run(command, capture_output=True, text=True, env=os.environ.copy())
        wall = time.perf_counter() - began
        if done.returncode != 0:
            sys.exit(f"the sweep failed: {done.stderr.strip()}")
        usage = resource.getrusage(resource.RUSAGE_CHILDREN)
        size = target.stat().st_size
    scenes = args.speeds * args.obliquities
    print(done.stdout.strip())
    print(
        f"{scenes:,} scenes: {wall:.1f} s wall ({wall / scenes * 1e6:.0f} us per scene), "
        f"{usage.ru_utime + usage.ru_stime:.1f} s CPU, peak RSS {usage.ru_maxrss / 1024:.0f} MB "
        f"(Linux: ru_maxrss in kB), CSV {size / 1e6:.0f} MB"
    )


if __name__ == "__main__":
    main()
