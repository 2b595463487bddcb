"""What stepping onto the force's branch surfaces saves (dopri5's ``branch_landing``).

For each failure model, on the seeded benchmark scenes: rejected steps and force
evaluations per scene, and the largest errors against solve_ivp DOP853 at rtol 1e-12,
with landing (the default) and without (steps straddle the surfaces). These are the
figures the tests used to pin as ratios (tests assert correctness; this prints cost).

Run:  python benchmarks/branch_landing.py [--scenes 500]
"""

from __future__ import annotations

import argparse

import numpy as np
from scenes import benchmark_batch

import plateimpact as pi


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--scenes", type=int, default=500)
    parser.add_argument("--rtol", type=float, default=1e-8)
    args = parser.parse_args()
    batch = benchmark_batch(args.scenes)
    speed = batch.impact_speed
    print(f"{'failure':>10} {'landing':>8} {'rejected/scene':>15} {'evals/scene':>12} "
          f"{'max dV/Vs':>10} {'max dtheta deg':>15}")  # fmt: skip
    for failure in ("plugging", "hinge"):
        reference = pi.Simulation.from_names(
            failure=failure, integrator="solve_ivp", integrator_settings={"rtol": 1e-12}
        ).run_batch(batch)
        for landing in (True, False):
            settings = {"rtol": args.rtol, "branch_landing": landing}
            result = pi.Simulation.from_names(
                failure=failure, integrator_settings=settings
            ).run_batch(batch)
            same = result.outcome == reference.outcome
            flying = same & (reference.outcome != pi.Outcome.EMBEDMENT)
            speed_error = np.max(
                np.abs(result.exit_speed - reference.exit_speed)[same] / speed[same]
            )
            turn_error = np.degrees(
                np.max(np.abs(result.exit_obliquity - reference.exit_obliquity)[flying])
            )
            print(
                f"{failure:>10} {landing!s:>8} {result.stats['rejected_steps'] / batch.size:15.1f} "
                f"{result.stats['force_evaluations'] / batch.size:12.0f} {speed_error:10.2e} "
                f"{turn_error:15.2e}  (outcome mismatches {int(np.sum(~same))})"
            )


if __name__ == "__main__":
    main()
