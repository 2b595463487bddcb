"""Reading a large shot file: the time to the first error when line 2 is bad, and the time
and peak memory of reading it whole (docs/robustness.md, "Every accepted request bounded").

    python benchmarks/shot_reading.py [--shots 1000000]

Writes two files of ``--shots`` rows (about 98 bytes a row, with a ``source`` text on
each) into a temporary directory, one with a bad impact speed on line 2, and reads each
with ``pi.Shots.from_csv`` in a fresh process: the seconds inside ``from_csv`` and the
process's peak resident memory.
"""

from __future__ import annotations

import argparse
import random
import resource
import subprocess
import sys
import tempfile
from pathlib import Path

HEADER = (
    "impact_speed_m_s,impact_obliquity_deg,outcome,residual_speed_m_s,exit_obliquity_deg,"
    "weight,source\n"
)
READ = """
import sys, time
import plateimpact as pi
began = time.perf_counter()
try:
    found = f"{len(pi.Shots.from_csv(sys.argv[1])):,} shots"
except pi.ShotDataError as exc:
    found = str(exc).rsplit(": ", 2)[-2][:60] + " ..."
print(f"{time.perf_counter() - began:.2f} s: {found}")
"""


def write(path: Path, shots: int, bad_line_2: bool) -> None:
    rng = random.Random(1)
    with path.open("w") as out:
        out.write(HEADER)
        for i in range(shots):
            v, o = rng.uniform(200, 900), rng.choice([0, 15, 30, 45, 60])
            source = f"range A test series 2024-03 plate lot 7 gun 2 shot {i:07d}"
            if bad_line_2 and i == 0:
                out.write(f"fast,{o},perforation,100,,1,{source}\n")
            elif v > 500:
                out.write(
                    f"{v:.6f},{o},perforation,{(v - 500) * 0.8 + 1:.6f},{o * 0.9:.4f},1,{source}\n"
                )
            else:
                out.write(f"{v:.6f},{o},embedment,0,,1,{source}\n")


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--shots", type=int, default=1_000_000)
    args = parser.parse_args()
    with tempfile.TemporaryDirectory() as directory:
        for name, bad in (("bad line 2", True), ("valid", False)):
            path = Path(directory) / "shots.csv"
            write(path, args.shots, bad)
            before = resource.getrusage(resource.RUSAGE_CHILDREN).ru_maxrss
            run = subprocess.run([sys.executable, "-c", READ, str(path)], capture_output=True,
                                 text=True, check=True)  # fmt: skip
            peak = resource.getrusage(resource.RUSAGE_CHILDREN).ru_maxrss
            size = path.stat().st_size / 1e6
            print(f"{name:10s} ({size:.1f} MB): {run.stdout.strip()}; peak resident "
                  f"{max(peak, before) / 1e3:.0f} MB")  # fmt: skip


if __name__ == "__main__":
    main()
