"""How well the calibration finds Table 1's a and b again from the model's own shots.

    python studies/calibration_recovery.py [--noise 0.02] [--seed 7] [--seeds 1]

For each Table-1 plate: 12 shots at normal incidence (the speeds of
tests/test_calibration.py), made at rtol 1e-10 and fitted at rtol 1e-8 (the default), so
that no fit recovers numbers it computed itself. Prints
the relative errors of a and b of the Newton iteration and of the direct fit, the Newton
steps from the documented start and from the thickness reading of eqs 42-43, then the
same fits with ``--noise`` (relative, on the residual speed) with their standard errors;
with ``--seeds N`` also the root mean square and largest of (fitted − Table 1) / standard
error over N noise draws (about 1 for honest standard errors). About 6 s, plus
3.5 s per extra seed.
"""

from __future__ import annotations

import argparse
import math
import time

import numpy as np

import plateimpact as pi
from plateimpact import presets
from plateimpact_plugins import report

SPHERE = presets.DEFAULT_SPHERE
FIT = pi.Simulation.from_names(integrator_settings={"rtol": 1e-8})
DATA = pi.Simulation.from_names(integrator_settings={"rtol": 1e-10})
SPEEDS = {  # [m/s], as in tests/test_calibration.py
    "2024-T3/1.27": np.linspace(130.0, 700.0, 12),
    "2024-T3/3.18": np.linspace(330.0, 1500.0, 12),
    "2024-T3/6.35": np.linspace(520.0, 1500.0, 12),
    "6061-T6/9.53": np.linspace(620.0, 1500.0, 12),
    "SAE1010/1.47": np.linspace(280.0, 1500.0, 12),
}


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--noise", type=float, default=0.02, help="relative noise [-]")
    parser.add_argument("--seed", type=int, default=7, help="random seed of the noise")
    parser.add_argument(
        "--seeds", type=int, default=1, help="repeat with this many seeds; print error/stderr"
    )
    args = parser.parse_args()
    started = time.perf_counter()
    print("noise-free: |relative error| of a, b; Newton steps (documented / thickness start)")
    for name, speeds in SPEEDS.items():
        plate = presets.plate(name)
        shots = pi.synthetic_shots(plate, SPHERE, speeds, simulation=DATA)
        newton = report.newton_fit(shots, plate, simulation=FIT)
        direct = report.direct_fit(shots, plate, simulation=FIT)
        dri = pi.fit_dri(shots.impact_speed, shots.residual_speed)
        volume = math.pi * SPHERE.radius**2 * plate.thickness
        start = report.energy_balance_start(dri.R, dri.V0, SPHERE, plate, volume=volume)
        thick = report.newton_fit(shots, plate, simulation=FIT, start=start)
        print(
            f"  {name:13s} newton a {abs(newton.a / plate.a - 1):.1e} b "
            f"{abs(newton.b / plate.b - 1):.1e} | direct a {abs(direct.a / plate.a - 1):.1e} "
            f"b {abs(direct.b / plate.b - 1):.1e} | steps {newton.iterations} / "
            f"{thick.iterations} | R {dri.R:.4f} V0 {dri.V0:.1f} m/s"
        )
    print(f"noise {args.noise:g} (seed {args.seed}): fitted/Table 1 - 1 (standard error)")
    for name, speeds in SPEEDS.items():
        plate = presets.plate(name)
        z = []  # (fitted - Table 1) / standard error, per seed: a, b of newton, of direct
        for seed in range(args.seed, args.seed + args.seeds):
            shots = pi.synthetic_shots(
                plate, SPHERE, speeds, noise=args.noise, seed=seed, simulation=DATA
            )
            fits = [
                report.newton_fit(shots, plate, simulation=FIT),
                report.direct_fit(shots, plate, simulation=FIT),
            ]
            z.append([(f.a - plate.a) / f.a_stderr for f in fits])
            z[-1] += [(f.b - plate.b) / f.b_stderr for f in fits]
            if seed == args.seed:
                cells = [
                    f"{f.method} a {f.a / plate.a - 1:+.3f} ({f.a_stderr / plate.a:.3f}) "
                    f"b {f.b / plate.b - 1:+.3f} ({f.b_stderr / plate.b:.3f})"
                    for f in fits
                ]
                print(f"  {name:13s} " + " | ".join(cells))
        if args.seeds > 1:
            z = np.array(z)
            rms, worst = np.sqrt(np.mean(z**2, axis=0)), np.max(np.abs(z), axis=0)
            print(
                f"  {'':13s} over {args.seeds} seeds, rms (max) of error/stderr: newton a "
                f"{rms[0]:.2f} ({worst[0]:.1f}) b {rms[2]:.2f} ({worst[2]:.1f}) | direct a "
                f"{rms[1]:.2f} ({worst[1]:.1f}) b {rms[3]:.2f} ({worst[3]:.1f})"
            )
    print(f"{time.perf_counter() - started:.1f} s")


if __name__ == "__main__":
    main()
