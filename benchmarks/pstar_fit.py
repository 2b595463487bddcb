"""P* (and α*) from oblique shots: how well a known value comes back, and what a fit costs.

python benchmarks/pstar_fit.py [--seeds 10] [--alpha-seeds 3] [--table-seeds 5]
                               [--write-shots FILE]

Shots are made by the model as the fit's probability model says (docs/calibration.md,
"P* and α* from oblique shots"): the true impact speed is the recorded one + N(0, s²),
s = 10 m/s; the outcome and residual speed are the model's there, the residual speed
+ N(0, σ_r²), σ_r = 5 m/s. For each seed it prints fit − truth in standard errors (z),
the standard error relative to the truth and the time per fit; then the mean and root
mean square of z (0 and 1 when the estimate is unbiased and its standard error honest)
and the largest |z|. Default finder and integrator (boundaries to 0.01 m/s, no band of
1 m/s missed, dopri5 at rtol 1e-8).

* ``P*``: 2024-T3/3.18 (P* = 3.0 mm), 8 shots at each of 30, 45 and 60 deg across
  their boundaries;
* ``P*, alpha*``: the same plate, 12 shots at each of 0, 30, 45 and 60 deg, α* started
  at 35 deg (truth 45);
* ``table``: SAE1010/1.47 shots made with a variable-P* table (ricochet and perforation
  P* 3.5 and 4.4 mm at 45 deg, 3.0 and 3.8 mm at 60 deg, 4.6 mm at 0 deg), fitted by
  obliquity.

``--write-shots FILE`` writes the first P* data set (seed 0) as a shot file, the example
of docs/calibration.md ("P* and α* from oblique shots").
"""

from __future__ import annotations

import argparse
import math
import time
from collections.abc import Callable

import numpy as np

import plateimpact as pi
from plateimpact import presets
from plateimpact.model.results import Outcome
from plateimpact_plugins import PstarTable, report

SPEED_SIGMA, RESIDUAL_SIGMA = 10.0, 5.0  # [m/s]
SPHERE = presets.DEFAULT_SPHERE
ALUMINIUM = presets.plate("2024-T3/3.18")
STEEL = presets.plate("SAE1010/1.47")
TABLE = [(0.0, 4.6, 4.6, 300.0, 330.0), (45.0, 3.5, 4.4, 344.0, 402.0),
         (60.0, 3.0, 3.8, 442.0, 536.0)]  # fmt: skip


def shots(
    simulation: pi.Simulation,
    plate: pi.Plate,
    groups: list[tuple[float, float, float, int]],
    seed: int,
) -> pi.Shots:
    """Shots at (obliquity [deg], lowest, highest speed [m/s], count) per group."""
    rng = np.random.default_rng(seed)
    speeds = np.concatenate([np.linspace(lo, hi, n) for _, lo, hi, n in groups])
    obliquities = np.radians(np.repeat([g[0] for g in groups], [g[3] for g in groups]))
    n = speeds.size
    true = speeds + SPEED_SIGMA * rng.standard_normal(n)
    labels = tuple(f"shot {i}" for i in range(n))
    blank = np.full(n, np.nan)
    truth = pi.Shots(true, obliquities, blank, blank, np.zeros(n, int), labels)
    result = simulation.run_batch(truth.scenes(SPHERE, plate))
    perforated = result.outcome == Outcome.PERFORATION
    noisy = result.exit_speed + RESIDUAL_SIGMA * rng.standard_normal(n)
    residual = np.where(perforated, np.maximum(noisy, 1.0), 0.0)
    return pi.Shots(speeds, obliquities, residual, blank, result.outcome.astype(int), labels)


def summary(name: str, z: list[float], relative: list[float], seconds: list[float]) -> None:
    values = np.array(z)
    print(
        f"{name}: mean z {values.mean():+.2f}, rms z {np.sqrt(np.mean(values**2)):.2f}, "
        f"largest |z| {np.abs(values).max():.2f} over {values.size} fits; standard error "
        f"{100 * np.mean(relative):.1f}% of the truth; {np.mean(seconds):.1f} s per fit"
    )


def timed(fit: Callable[..., object], *args: object, **kwargs: object) -> tuple[object, float]:
    began = time.perf_counter()
    found = fit(*args, **kwargs)
    return found, time.perf_counter() - began


ALUMINIUM_GROUPS = [(30.0, 360, 460, 8), (45.0, 430, 530, 8), (60.0, 600, 730, 8)]


def pstar_only(seeds: int) -> None:
    simulation = pi.Simulation.from_names()
    groups = ALUMINIUM_GROUPS
    z, relative, seconds = [], [], []
    for seed in range(seeds):
        data = shots(simulation, ALUMINIUM, groups, seed)
        fit, spent = timed(report.fit_pstar, data, ALUMINIUM, simulation=simulation)
        assert isinstance(fit, report.PstarFit)
        z.append((fit.pstar - 3e-3) / fit.pstar_stderr)
        relative.append(fit.pstar_stderr / 3e-3)
        seconds.append(spent)
        print(
            f"  P* seed {seed}: {fit.pstar * 1e3:.4f} ± {fit.pstar_stderr * 1e3:.4f} mm "
            f"(z {z[-1]:+.2f}), {fit.cost.evaluations} candidates in {fit.cost.batches} "
            f"batches, {spent:.1f} s",
            flush=True,
        )
    summary("P*", z, relative, seconds)


def with_alpha(seeds: int) -> None:
    simulation = pi.Simulation.from_names()
    groups = [(0.0, 340, 520, 12), (30.0, 360, 520, 12), (45.0, 430, 600, 12),
              (60.0, 600, 800, 12)]  # fmt: skip
    start = ALUMINIUM.with_constants(failure_angle=math.radians(35.0))
    zp, za, relative, relative_alpha, seconds = [], [], [], [], []
    for seed in range(seeds):
        data = shots(simulation, ALUMINIUM, groups, 100 + seed)
        fit, spent = timed(report.fit_pstar, data, start, simulation=simulation, fit_alpha=True)
        assert isinstance(fit, report.PstarFit)
        e = fit.estimate
        zp.append((e.pstar - 3e-3) / e.pstar_stderr)
        za.append((e.alpha - math.radians(45.0)) / e.alpha_stderr)
        relative.append(e.pstar_stderr / 3e-3)
        relative_alpha.append(e.alpha_stderr / math.radians(45.0))
        seconds.append(spent)
        print(
            f"  P*, alpha* seed {seed}: P* {e.pstar * 1e3:.4f} ± {e.pstar_stderr * 1e3:.4f} "
            f"mm (z {zp[-1]:+.2f}), alpha* {math.degrees(e.alpha):.2f} ± "
            f"{math.degrees(e.alpha_stderr):.2f} deg (z {za[-1]:+.2f}), correlation "
            f"{e.correlation:+.3f}; {fit.cost.evaluations} candidates, {spent:.1f} s",
            flush=True,
        )
    summary("P* (alpha* fitted)", zp, relative, seconds)
    summary("alpha*", za, relative_alpha, seconds)


def table(seeds: int) -> None:
    made_by = pi.Simulation.from_names(
        failure="variable-pstar", failure_settings={"table": PstarTable.from_rows(TABLE)}
    )
    simulation = pi.Simulation.from_names()
    groups = [(0.0, 290, 370, 10), (45.0, 310, 450, 14), (60.0, 410, 580, 14)]
    truth = {(row[0], "ricochet"): row[1] for row in TABLE[1:]}
    truth |= {(row[0], "perforation"): row[2] for row in TABLE}
    z, relative, seconds = [], [], []
    for seed in range(seeds):
        data = shots(made_by, STEEL, groups, 200 + seed)
        model = pi.ProbabilityModel(residual_sigma=RESIDUAL_SIGMA)
        fit, spent = timed(
            report.fit_pstar_by_obliquity, data, STEEL, simulation=simulation, model=model
        )
        assert isinstance(fit, report.PstarTableFit)
        parts = []
        for row in fit.rows:
            degrees = round(math.degrees(row.obliquity), 6)
            for name, e in (("ricochet", row.ricochet), ("perforation", row.perforation)):
                if (degrees, name) in truth and e.identified:
                    true = truth[degrees, name] * 1e-3
                    z.append((e.pstar - true) / e.pstar_stderr)
                    relative.append(e.pstar_stderr / true)
                    parts.append(f"{degrees:g} {name[:4]} {z[-1]:+.2f}")
        seconds.append(spent)
        print(
            f"  table seed {seed}: z {', '.join(parts)}; {fit.cost.evaluations} candidates "
            f"in {fit.cost.batches} batches, {spent:.1f} s",
            flush=True,
        )
    summary("table (5 values per fit)", z, relative, seconds)


def main() -> None:
    parser = argparse.ArgumentParser(description=(__doc__ or "").splitlines()[0])
    parser.add_argument("--seeds", type=int, default=10, help="P* fits (default 10)")
    parser.add_argument("--alpha-seeds", type=int, default=3, help="P*, alpha* fits")
    parser.add_argument("--table-seeds", type=int, default=5, help="by-obliquity fits")
    parser.add_argument("--write-shots", metavar="FILE", help="write the seed-0 P* shots here")
    args = parser.parse_args()
    if args.write_shots:
        data = shots(pi.Simulation.from_names(), ALUMINIUM, ALUMINIUM_GROUPS, 0)
        comment = "synthetic: 2024-T3/3.18 (P* = 3 mm), benchmarks/pstar_fit.py seed 0"
        with open(args.write_shots, "w", encoding="utf-8") as handle:
            handle.write(data.to_csv_text([comment]))
    if args.seeds:
        pstar_only(args.seeds)
    if args.table_seeds:
        table(args.table_seeds)
    if args.alpha_seeds:
        with_alpha(args.alpha_seeds)


if __name__ == "__main__":
    main()
