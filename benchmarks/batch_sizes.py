"""Cost per scene of small and large batches on the compiled path (one thread).

The compiled path steps WIDTH scenes together (solve/compiled/lane_store.py); a batch
with fewer scenes leaves lanes idle, which compute too. This prints the wall time per
scene [us] of the first n benchmark scenes for n from 1 to 2,000, each the mean of
repeated runs after a warm-up, including the run's fixed cost in Python.

Run:  python benchmarks/batch_sizes.py
"""

from __future__ import annotations

import time

import attrs
import numpy as np
from scenes import benchmark_batch

import plateimpact as pi
from plateimpact.solve.compiled import engine
from plateimpact.solve.compiled.lane_store import WIDTH

SIZES = (1, 8, 16, 40, 100, 400, 2000)


def main() -> None:
    engine.set_threads(1)
    simulation = attrs.evolve(pi.Simulation.from_names(), engine="compiled")
    every = benchmark_batch(max(SIZES))
    print(f"compiled path, {WIDTH} lanes, one thread: us per scene by batch size")
    for n in SIZES:
        batch = every.take(np.arange(n))
        simulation.run_batch(batch)  # warm-up (and the program's compile or load)
        repeats = max(3, 2000 // n)
        start = time.perf_counter()
        for _ in range(repeats):
            simulation.run_batch(batch)
        took = (time.perf_counter() - start) / repeats
        print(f"  {n:5d} scenes: {took / n * 1e6:7.1f} us per scene")


if __name__ == "__main__":
    main()
