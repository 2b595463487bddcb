"""Limits and outcome maps: run time, scenes, and how well the boundaries hold.

python benchmarks/limits.py [--jobs 2]

For each of the report's five plates (default sphere, plugging, dopri5):
* the limits of 18 obliquities (0-85 deg by 5) over 50-2000 m/s, boundaries to 0.01 m/s,
  no band of 1 m/s missed (issue 16 asks for under 5 s);
* a 200 x 86 outcome map (50-2000 m/s, 0-85 deg) with its boundaries (under 5 s);
and, on the 18-line request of each plate,
* the tolerance: each boundary against the same boundary located to 1e-4 m/s (the
  midpoint should be within half the tolerance);
* the resolution: the bands found with a 0.1 m/s scan that a 1 m/s scan missed (none
  wider than 1 m/s may be missing; narrower ones are reported).
Times are wall times of one run on this machine, after a warm-up.
"""

from __future__ import annotations

import argparse
import time
from concurrent.futures import Executor, ProcessPoolExecutor

import numpy as np

import plateimpact as pi
from plateimpact import limits, presets

OBLIQUITIES = np.radians(np.arange(0.0, 86.0, 5.0))


def boundaries(found: limits.Limits) -> list[tuple[int, float, int, int]]:
    return [
        (k, b.at, b.below.code, b.above.code)
        for k, line in enumerate(found.lines)
        for b in line.boundaries
    ]


def accuracy(
    simulation: pi.Simulation, plate: pi.Plate, found: limits.Limits, executor: Executor | None
) -> tuple[float, list[float], bool]:
    """The largest |at - at at 1e-4 m/s| / tolerance, the widths of the bands a 0.1 m/s
    scan finds that ``found`` misses, and whether the 1e-4 m/s run has the same
    boundaries."""
    sphere = presets.DEFAULT_SPHERE
    fine = limits.along_speed(
        simulation, sphere, plate, OBLIQUITIES, tolerance=1e-4, executor=executor
    )
    ours, theirs = boundaries(found), boundaries(fine)
    same = len(ours) == len(theirs) and all(
        a[0] == b[0] and a[2:] == b[2:] for a, b in zip(ours, theirs, strict=True)
    )
    worst = (
        max(abs(a[1] - b[1]) for a, b in zip(ours, theirs, strict=True)) / found.tolerance
        if same
        else float("nan")
    )
    dense = limits.along_speed(
        simulation, sphere, plate, OBLIQUITIES, resolution=0.1, executor=executor
    )
    missed = []  # bands of the 0.1 m/s scan whose middle the 1 m/s result puts elsewhere
    for coarse, finer in zip(found.lines, dense.lines, strict=True):
        for band in finer.bands:
            middle = 0.5 * (band.start + band.end)
            held = next(b for b in coarse.bands if b.start <= middle <= b.end)
            if held.regime != band.regime:
                missed.append(band.width)
    return worst, missed, same


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--jobs", type=int, default=1, help="worker processes (default 1)")
    parser.add_argument("--quick", action="store_true", help="times only (no accuracy checks)")
    args = parser.parse_args()
    executor = ProcessPoolExecutor(args.jobs) if args.jobs > 1 else None
    simulation = pi.Simulation.from_names()
    sphere = presets.DEFAULT_SPHERE
    warm = presets.plate("2024-T3/3.18")
    limits.along_speed(simulation, sphere, warm, [0.5], (300.0, 400.0), executor=executor)

    print(f"jobs: {args.jobs}")
    header = (
        "plate           18 lines: s  scenes  passes | map 200x86: s  scenes | "
        "max |at - fine| / tol | missed bands (widest, m/s)"
    )
    print(header)
    for name in presets.PLATES:
        plate = presets.plate(name)
        start = time.perf_counter()
        found = limits.along_speed(simulation, sphere, plate, OBLIQUITIES, executor=executor)
        lines_seconds = time.perf_counter() - start
        start = time.perf_counter()
        drawn = limits.outcome_map(simulation, sphere, plate, executor=executor)
        map_seconds = time.perf_counter() - start

        worst, missed, same = float("nan"), list[float](), True
        if not args.quick:
            worst, missed, same = accuracy(simulation, plate, found, executor)
        print(
            f"{name:15s} {lines_seconds:9.2f}  {found.scenes:6d}  {found.passes:6d} | "
            f"{map_seconds:13.2f}  {drawn.limits.scenes:6d} | {worst:20.3f} | "
            f"{len(missed)}"
            + (f" ({max(missed):.3f})" if missed else "")
            + ("" if same else "  boundaries differ at 1e-4 m/s!")
        )
    if executor is not None:
        executor.shutdown()


if __name__ == "__main__":
    main()
