"""Accuracy and cost of the report's segment integrator against its step.

Prints, for each step (fraction of Rs/Vs):
  * normal incidence on intact plates (all five presets, 100–1500 m/s): max relative
    error of the maximum penetration against the energy-integral closed form;
  * oblique scenes with plugging failure (all outcomes): max error of exit speed
    (relative to impact speed) and exit obliquity [deg] against a Richardson-extrapolated
    reference (first order: 2 x(h/2) − x(h) from the two finest steps);
  * time per scene [ms] (minimum of 3 runs) and force evaluations per scene.

Run:  python benchmarks/segment_convergence.py
"""

from __future__ import annotations

import time

import numpy as np
from scipy.optimize import brentq

import plateimpact as pi
from plateimpact import presets

STEPS = [1e-2, 3e-3, 1e-3, 3e-4, 1e-4]
REFERENCE_STEPS = (1e-4, 5e-5)
#: The fine steps run contacts of up to 33 Rs/Vs (1500 m/s at normal incidence), 83,000
#: steps at 5e-5: more than the default work bound (20,000), raised here on purpose.
MAX_STEPS = 200_000


def segment(step: float, **names: str) -> pi.Simulation:
    settings = {"step": step, "max_steps": MAX_STEPS}
    return pi.Simulation.from_names(integrator="segment", integrator_settings=settings, **names)


def closed_form_max_penetration(sphere, plate, speed, rest_fraction=0.01):
    rs, m, a, b = sphere.radius, sphere.mass, plate.a, plate.b

    def g(p):
        if p <= rs:
            return np.pi * (rs * p**2 - p**3 / 3)
        return 2 * np.pi * rs**3 / 3 + np.pi * rs**2 * (p - rs)

    target = m / (2 * b) * np.log((a + b * speed**2) / (a + b * (rest_fraction * speed) ** 2))
    return brentq(lambda p: g(p) - target, 0, 50 * rs, xtol=1e-16)


def timed(simulation, scenes, repeats=3):
    best = np.inf
    for _ in range(repeats):
        start = time.perf_counter()
        result = simulation.run_batch(scenes)
        best = min(best, time.perf_counter() - start)
    return result, best / len(scenes)


def main() -> None:
    sphere = presets.DEFAULT_SPHERE
    normal = [
        pi.Scene(sphere, plate, speed, 0.0)
        for plate in presets.PLATES.values()
        for speed in (100.0, 400.0, 900.0, 1500.0)
    ]
    exact = np.array([closed_form_max_penetration(sphere, s.plate, s.impact_speed) for s in normal])
    rng = np.random.default_rng(5844)
    names = list(presets.PLATES)
    oblique = [
        pi.Scene(
            sphere,
            presets.plate(names[i % 5]),
            rng.uniform(50, 1500),
            np.radians(rng.uniform(10, 70)),
        )
        for i in range(20)
    ]
    fine = [segment(s).run_batch(oblique) for s in REFERENCE_STEPS]
    ref_speed = 2 * fine[1].exit_speed - fine[0].exit_speed
    ref_obliquity = 2 * fine[1].exit_obliquity - fine[0].exit_obliquity
    speeds = np.array([s.impact_speed for s in oblique])
    flying = fine[1].outcome != pi.Outcome.EMBEDMENT

    print(
        f"{'step':>8s} {'P_max rel err':>14s} {'exit V err/Vs':>14s} {'exit θ err deg':>15s}"
        f" {'mismatch':>8s} {'ms/scene':>9s} {'evals/scene':>11s}"
    )
    for step in STEPS:
        intact, plugging = segment(step, failure="intact"), segment(step)
        n_res, _ = timed(intact, normal, repeats=1)
        o_res, per_scene = timed(plugging, oblique)
        p_err = np.max(np.abs(n_res.max_penetration - exact) / exact)
        v_err = np.max(np.abs(o_res.exit_speed - ref_speed) / speeds)
        t_err = np.degrees(np.max(np.abs(o_res.exit_obliquity - ref_obliquity)[flying]))
        mismatch = int(np.sum(o_res.outcome != fine[1].outcome))
        evals = o_res.stats["force_evaluations"] / len(oblique)
        print(
            f"{step:8.0e} {p_err:14.2e} {v_err:14.2e} {t_err:15.2e} {mismatch:8d}"
            f" {per_scene * 1e3:9.2f} {evals:11.0f}"
        )


if __name__ == "__main__":
    main()
