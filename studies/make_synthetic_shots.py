"""Synthetic shot data for trying the calibration: the model's own residual speeds at
normal incidence from the report's Table-1 constants, plus measurement noise.

    python studies/make_synthetic_shots.py [--plate 2024-T3/3.18] [--noise 0.02]
        [--seed 20240303] [--count 15] [--out studies/data/shots_2024T3_3.18mm.csv]

The file it writes says in its header that it is synthetic. Impact speeds are spread
evenly from 0.7 V0 to 1500 m/s with ±5 m/s of jitter (V0 from a coarse model sweep), and
rounded to 0.1 m/s; each residual speed is the model's times 1 + noise·N(0, 1).
Then ``plateimpact calibrate`` on the file should give back Table 1's a and b within
its reported standard errors (README, "Calibration").
"""

from __future__ import annotations

import argparse
from pathlib import Path

import numpy as np

import plateimpact as pi
from plateimpact import presets
from plateimpact.units import deg, g, mm

SPHERE = presets.DEFAULT_SPHERE
HERE = Path(__file__).resolve().parent


def ballistic_limit(plate: pi.Plate) -> float:
    """The model's ballistic limit at normal incidence [m/s], to 1 m/s (one batch)."""
    speeds = np.arange(10.0, 1501.0, 1.0)
    result = pi.Simulation.from_names().run_batch(
        pi.SceneBatch.grid(SPHERE, plate, speeds, np.zeros(1))
    )
    return float(speeds[np.argmax(result.outcome == pi.Outcome.PERFORATION)])


def make_shots(plate_name: str, noise: float, seed: int, count: int) -> pi.Shots:
    """``count`` synthetic shots of the preset ``plate_name`` (see the module's text)."""
    plate = presets.plate(plate_name)
    rng = np.random.default_rng(seed)
    speeds = np.linspace(0.7 * ballistic_limit(plate), 1500.0, count)
    speeds = np.round(speeds + rng.uniform(-5.0, 5.0, count), 1)
    return pi.synthetic_shots(plate, SPHERE, speeds, noise=noise, seed=seed + 1)


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--plate", default="2024-T3/3.18", help="Table-1 preset")
    parser.add_argument("--noise", type=float, default=0.02, help="relative noise [-]")
    parser.add_argument("--seed", type=int, default=20240303, help="random seed")
    parser.add_argument("--count", type=int, default=15, help="number of shots")
    parser.add_argument("--out", type=Path, help="CSV to write")
    args = parser.parse_args()
    plate = presets.plate(args.plate)
    tag = args.plate.replace("-", "").replace("/", "_")
    out = args.out or HERE / "data" / f"shots_{tag}mm.csv"
    shots = make_shots(args.plate, args.noise, args.seed, args.count)
    comments = [
        "SYNTHETIC DATA, NOT FIRINGS: residual speeds computed by plateimpact's model, with noise.",
        f"Made by studies/make_synthetic_shots.py --plate {args.plate} --noise {args.noise:g} "
        f"--seed {args.seed} --count {args.count}",
        f"from Table 1 of NWC TP 5844 for {args.plate}: a = {plate.a:.4g} N/m^2, "
        f"b = {plate.b:.4g} kg/m^3, P* = {plate.critical_penetration / mm:g} mm, "
        f"alpha* = {plate.failure_angle / deg:g} deg;",
        f"sphere radius {SPHERE.radius / mm:g} mm, mass {SPHERE.mass / g:.4f} g; plugging, "
        f"dopri5 at its default rtol; residual speed x (1 + {args.noise:g} N(0,1)).",
    ]
    out.write_text(shots.to_csv_text(comments))
    print(f"wrote {len(shots)} shots ({int(shots.perforated.sum())} perforating) to {out}")


if __name__ == "__main__":
    main()
