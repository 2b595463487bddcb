"""Stress: a million random scenes through the default integrator.

Scenes are drawn log-uniformly over the domain of the property tests (radius 0.5–20 mm,
density 1–20 g/cm³, speed 1 m/s–5 km/s, a 3e7–3e10 N/m², b 30–3e4 kg/m³, P* and thickness
0.1–10 Rs, α* 10–80°; obliquity uniform in 0–89.9°, 1% exactly 0), seeded, in batches on
a process pool. For every scene: outputs finite, an outcome assigned, exit speed <= impact
speed, a ricochet leaving in (90°, 180°], a perforation in [0°, 90°), a normal impact
never turning (perforation straight through, ricochet straight back); in 1% of the
batches the trajectories are recorded and the speed must never rise along them (beyond
1e-9 Vs). Prints the counts (all must be 0) and the wall time.

Run:  python benchmarks/stress.py [--scenes 1000000] [--batch 10000] [--workers 2]
"""

from __future__ import annotations

import argparse
import os
import time
from concurrent.futures import ProcessPoolExecutor

import numpy as np

import plateimpact as pi
from plateimpact.units import deg, mm

FIELDS = ("nan", "unclassified", "speed_gain", "exit_direction", "normal_turned", "speed_rise")


def random_batch(size: int, seed: int) -> pi.SceneBatch:
    rng = np.random.default_rng(seed)

    def log_uniform(low: float, high: float) -> np.ndarray:
        return np.exp(rng.uniform(np.log(low), np.log(high), size))

    radius = log_uniform(0.5 * mm, 20 * mm)
    density = log_uniform(1000.0, 20000.0)
    obliquity = rng.uniform(0.0, 89.9, size) * deg
    obliquity[rng.random(size) < 0.01] = 0.0
    return pi.SceneBatch(
        {
            "radius": radius,
            "mass": density * 4.0 / 3.0 * np.pi * radius**3,
            "thickness": log_uniform(0.1, 10.0) * radius,
            "a": log_uniform(3e7, 3e10),
            "b": log_uniform(30.0, 3e4),
            "critical_penetration": log_uniform(0.1, 10.0) * radius,
            "failure_angle": rng.uniform(10.0, 80.0, size) * deg,
            "impact_speed": log_uniform(1.0, 5000.0),
            "impact_obliquity": obliquity,
        }
    )


def check(size: int, seed: int, record: bool) -> dict[str, int]:
    """Run one batch and count the scenes that break each invariant."""
    batch = random_batch(size, seed)
    result = pi.Simulation.from_names().run_batch(batch, record_trajectory=record)
    outcome, speed, direction = result.outcome, result.exit_speed, result.exit_obliquity
    finite = np.isfinite(speed) & np.isfinite(direction) & np.isfinite(result.contact_time)
    ricochet, perforation = outcome == pi.Outcome.RICOCHET, outcome == pi.Outcome.PERFORATION
    normal = batch.impact_obliquity == 0.0
    counts = {
        "nan": int(np.count_nonzero(~finite)),
        "unclassified": int(np.count_nonzero(~np.isin(outcome, [1, 2, 3]))),
        "speed_gain": int(np.count_nonzero(speed > batch.impact_speed)),
        "exit_direction": int(
            np.count_nonzero(ricochet & ~((direction > 0.5 * np.pi) & (direction <= np.pi)))
            + np.count_nonzero(perforation & ~((direction >= 0.0) & (direction < 0.5 * np.pi)))
        ),
        "normal_turned": int(
            np.count_nonzero(normal & perforation & (direction != 0.0))
            + np.count_nonzero(normal & ricochet & (direction != np.pi))
        ),
        "speed_rise": 0,
    }
    if record:
        for i in range(size):
            path = result.trajectory_of(i)
            counts["speed_rise"] += int(np.any(np.diff(path.speed) > 1e-9 * path.speed[0]))
    counts["scenes"] = size
    return counts


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--scenes", type=int, default=1_000_000)
    parser.add_argument("--batch", type=int, default=10_000)
    parser.add_argument("--workers", type=int, default=os.cpu_count() or 1)
    args = parser.parse_args()
    batches = -(-args.scenes // args.batch)
    totals = dict.fromkeys((*FIELDS, "scenes"), 0)
    start = time.perf_counter()
    with ProcessPoolExecutor(args.workers) as pool:
        futures = [
            pool.submit(check, min(args.batch, args.scenes - k * args.batch), k, k % 100 == 0)
            for k in range(batches)
        ]
        for future in futures:
            for key, value in future.result().items():
                totals[key] += value
    wall = time.perf_counter() - start
    print(f"{totals['scenes']} random scenes in {batches} batches, {args.workers} processes")
    for key in FIELDS:
        print(f"  {key:15s} {totals[key]}")
    print(f"wall time {wall:.0f} s ({wall / totals['scenes'] * 1e6:.0f} us per scene)")


if __name__ == "__main__":
    main()
