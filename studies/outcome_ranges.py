"""Outcome ranges of the report's five plates: where a 6.35-mm steel sphere ricochets,
embeds or perforates, by obliquity (the ranges the 1976 computation had to find first).

Run:  python studies/outcome_ranges.py [--integrator dopri5|segment|solve_ivp]

Prints, per plate and obliquity, the impact-speed ranges [m/s] of each outcome on a
25 m/s grid, marking ricochets after plate failure (the thin-plate band) with "*".
"""

from __future__ import annotations

import argparse
import itertools
import time

import numpy as np

import plateimpact as pi
from plateimpact import presets

SPEEDS = np.arange(25.0, 1501.0, 25.0)  # [m/s]
OBLIQUITIES = (0.0, 20.0, 30.0, 45.0, 60.0)  # [deg]


def ranges(outcome: np.ndarray, failed: np.ndarray) -> str:
    """'R 25–300 | R* 325–350 | E 375–500 | P 525–1500' from per-speed outcomes."""
    codes = np.where((outcome == pi.Outcome.RICOCHET) & failed, 0, outcome)
    labels = {0: "R*", 1: "R", 2: "E", 3: "P"}
    parts = []
    for code, run in itertools.groupby(zip(codes, SPEEDS, strict=True), key=lambda cv: cv[0]):
        run = [v for _, v in run]
        parts.append(f"{labels[int(code)]} {run[0]:.0f}–{run[-1]:.0f}")
    return " | ".join(parts)


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--integrator", default="dopri5", help="integrator by name")
    args = parser.parse_args()

    simulation = pi.Simulation.from_names(integrator=args.integrator)
    cases = list(itertools.product(presets.PLATES, OBLIQUITIES))
    batch = pi.SceneBatch.concat(
        pi.SceneBatch.grid(presets.DEFAULT_SPHERE, presets.plate(name), SPEEDS, [np.radians(ob)])
        for name, ob in cases
    )
    start = time.perf_counter()
    result = simulation.run_batch(batch)
    elapsed = time.perf_counter() - start

    n = SPEEDS.size
    for k, (name, obliquity) in enumerate(cases):
        part = slice(k * n, (k + 1) * n)
        outcome_ranges = ranges(result.outcome[part], result.plate_failed[part])
        print(f"{name:14s} {obliquity:4.0f}°  {outcome_ranges}")
    print(
        f"\n{batch.size} scenes in {elapsed:.1f} s ({simulation.integrator.name} "
        f"{simulation.integrator.settings()}); R* = ricochet after plate failure"
    )


if __name__ == "__main__":
    main()
