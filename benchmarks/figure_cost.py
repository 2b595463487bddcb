"""The cost of the outcome-map figure: drawing and saving the five plates' maps as
`plateimpact reproduce` draws ``outcome_maps.png`` (issue 23, item 5).

python benchmarks/figure_cost.py [--archive report/report.h5] [--repeats 5] [--plates 5]
                                 [--dpi 150] [--out maps.png]

The maps are those ``reproduce`` stored in ``--archive`` (``limits/map_PLATE``), or by
default synthetic maps on ``reproduce``'s grid (100 speeds over 50-2000 m/s, 43
obliquities 0-84 deg, five plates), whose boundaries are closed-form curves, so no scene
runs; ``--plates 1`` draws the first alone, as ``plateimpact map`` does. Prints each
repetition's time of drawing and of saving [s], their medians and the figure's size.
Compare two versions of the code by running this script with each, in turn, on the
same maps.
"""

from __future__ import annotations

import argparse
import math
import statistics
import tempfile
import time
from pathlib import Path

import numpy as np

from plateimpact import limits, presets
from plateimpact.figures import saving
from plateimpact.figures.limits_and_maps import plot_outcome_map

RICOCHET, EMBEDMENT, PERFORATION = (limits.REGIMES[k] for k in (0, 2, 4))
SPEEDS = np.linspace(50.0, 2000.0, 100)  # [m/s], reproduce's map grid
OBLIQUITIES = np.radians(np.arange(0.0, 85.0, 2.0))  # [rad]


def synthetic_map(plate: str, ballistic: float, ricochet_from: float) -> limits.OutcomeMap:
    """A map with the shape of the report's: perforation above a ballistic limit
    ``ballistic`` / cos(obliquity) [m/s], embedment below it, ricochet above
    ``ricochet_from`` [rad] below a ricochet limit rising to the ballistic limit."""
    lines, regime = [], np.empty((OBLIQUITIES.size, SPEEDS.size), dtype=int)
    for row, obliquity in enumerate(OBLIQUITIES):
        limit = ballistic / math.cos(obliquity)
        steps = [(limit, EMBEDMENT, PERFORATION)]
        if obliquity > ricochet_from:  # ricochet below a fraction of the ballistic limit
            share = min(1.0, 3.0 * (obliquity - ricochet_from))
            steps = [(50.0 + share * (limit - 50.0), RICOCHET, EMBEDMENT), *steps]
        kept = [(at, below, above) for at, below, above in steps if 50.0 < at < 2000.0]
        bounds = tuple(limits.Boundary(at - 0.005, at + 0.005, b, a) for at, b, a in kept)
        first = RICOCHET if obliquity > ricochet_from else EMBEDMENT
        lines.append(limits.LimitLine(limits.SPEED, float(obliquity), 50.0, 2000.0, bounds, first))
        regime[row] = first.code
        for at, _, above in kept:
            regime[row, SPEEDS > at] = above.code
    exit_speed = np.sqrt(
        np.clip(SPEEDS**2 - (ballistic / np.cos(OBLIQUITIES[:, None])) ** 2, 0, None)
    )
    found = limits.Limits(
        limits.SPEED, tuple(lines), 0.01, float(SPEEDS[1] - SPEEDS[0]), presets.DEFAULT_SPHERE,
        presets.plate(plate), {"resistance": "poncelet", "failure": "plugging",
                               "integrator": "dopri5"}, 0, 0, 0.0,
    )  # fmt: skip
    return limits.OutcomeMap(SPEEDS, OBLIQUITIES, regime, exit_speed, np.zeros_like(exit_speed),
                             found)  # fmt: skip


def maps_of(archive: str | None) -> list[tuple[str, limits.OutcomeMap]]:
    if archive is None:
        shapes = [(150.0, 1.2), (380.0, 1.1), (600.0, 0.3), (700.0, 0.25), (300.0, 0.9)]
        return [(plate, synthetic_map(plate, *shape))
                for plate, shape in zip(presets.PLATES, shapes, strict=True)]  # fmt: skip
    names = [f"map_{plate.replace('/', '_')}" for plate in presets.PLATES]
    found = [limits.read_limits(archive, name) for name in names]
    return [(plate, m) for plate, m in zip(presets.PLATES, found, strict=True)
            if isinstance(m, limits.OutcomeMap)]  # fmt: skip


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--archive", help="read the maps reproduce stored here")
    parser.add_argument("--repeats", type=int, default=5)
    parser.add_argument("--plates", type=int, default=5, choices=range(1, 6))
    parser.add_argument("--dpi", type=float, default=saving.DPI)
    parser.add_argument("--out", help="keep the last figure here (its extension: the format)")
    args = parser.parse_args()
    maps = maps_of(args.archive)[: args.plates]
    shape = f"{len(maps)} maps of {maps[0][1].shape[0]} x {maps[0][1].shape[1]}"
    print(f"{shape} ({'synthetic' if args.archive is None else args.archive})")
    with tempfile.TemporaryDirectory() as scratch:
        path = Path(args.out or Path(scratch) / "outcome_maps.png")
        draws, saves = [], []
        for _ in range(args.repeats):
            start = time.perf_counter()
            fig = plot_outcome_map(maps)
            drawn = time.perf_counter()
            saving.save(fig, path, dpi=args.dpi)
            draws.append(drawn - start)
            saves.append(time.perf_counter() - drawn)
            print(f"  draw {draws[-1]:.3f} s, save {saves[-1]:.3f} s")
        total = [d + s for d, s in zip(draws, saves, strict=True)]
        width, height = fig.get_size_inches()
        print(f"median of {args.repeats}: draw {statistics.median(draws):.3f} s, save "
              f"{statistics.median(saves):.3f} s, draw + save {statistics.median(total):.3f} s "
              f"(min {min(total):.3f}, max {max(total):.3f}); {width:.2f} x {height:.2f} in = "
              f"{round(width * args.dpi)} x {round(height * args.dpi)} px, "
              f"{path.stat().st_size / 1e3:.0f} kB")  # fmt: skip


if __name__ == "__main__":
    main()
