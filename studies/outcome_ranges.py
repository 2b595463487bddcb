"""Outcome ranges of the report's five plates: where a 6.35-mm steel sphere ricochets,
embeds or perforates, by obliquity (the ranges the 1976 computation had to find first).

Run:  python studies/outcome_ranges.py [--integrator dopri5|segment|solve_ivp]

Prints, per plate and obliquity, the impact-speed range [m/s] of each outcome band over
25-1500 m/s, each boundary located to 0.01 m/s and no band of 1 m/s missed
(plateimpact.limits, docs/limits.md), marking the bands after plate failure with "*"
(R*: the thin-plate band, a ricochet off a plate that failed).
"""

from __future__ import annotations

import argparse
import time

import numpy as np

import plateimpact as pi
from plateimpact import limits, presets

SPEEDS = (25.0, 1500.0)  # [m/s]
OBLIQUITIES = (0.0, 20.0, 30.0, 45.0, 60.0)  # [deg]
SHORT = {"ricochet": "R", "embedment": "E", "perforation": "P"}


def ranges(line: limits.LimitLine) -> str:
    """'R 25.00–300.12 | R* 300.12–351.40 | E* 351.40–353.02 | P 353.02–1500.00'."""
    parts = []
    for band in line.bands:
        mark = (
            "*" if band.regime.plate_failed and band.regime.outcome.label != "perforation" else ""
        )
        parts.append(f"{SHORT[band.regime.outcome.label]}{mark} {band.start:.2f}–{band.end:.2f}")
    return " | ".join(parts)


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--integrator", default="dopri5", help="integrator by name")
    args = parser.parse_args()

    simulation = pi.Simulation.from_names(integrator=args.integrator)
    start, scenes = time.perf_counter(), 0
    for name in presets.PLATES:
        found = limits.along_speed(
            simulation, presets.DEFAULT_SPHERE, presets.plate(name), np.radians(OBLIQUITIES),
            SPEEDS,
        )  # fmt: skip
        scenes += found.scenes
        for obliquity, line in zip(OBLIQUITIES, found.lines, strict=True):
            print(f"{name:14s} {obliquity:4.0f}°  {ranges(line)}")
    print(
        f"\n{scenes} scenes in {time.perf_counter() - start:.1f} s ({simulation.integrator.name} "
        f"{simulation.integrator.settings()}); * = after plate failure"
    )


if __name__ == "__main__":
    main()
