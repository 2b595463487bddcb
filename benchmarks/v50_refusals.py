"""How often the V50 fit refused ordinary shots before (main@86344fb: scipy's trust-region
solver alone) and now (plateimpact.v50.solver), and what counting the bootstrap
resamples it failed on as flat curves did to the σ interval.

python benchmarks/v50_refusals.py [--orderings 200] [--sets 5000] [--resamples 1000]
    [--seed 0]

1. The 13-row weighted file tests/data/v50_weighted_13_rows.csv (53 rounds) in
   --orderings seeded row orders: how many the old solver refused, the solver now on the
   rows in that order, and fit_v50.
2. --sets seeded sets of 30 unit-weight shots (speeds uniform in 450–550 m/s,
   perforating with probability Φ((v − 500 m/s)/20 m/s)), probit and logit: how many
   each solver refused for not converging (a set with no zone of mixed results is
   refused by both, rightly, and counted apart).
3. The probit bootstrap of the 13-row file, --bootstrap-seeds seeds of --resamples
   resamples drawn as fit_v50 draws them (the rows in its order, a binomial count per
   row from the fitted curve): the 95 % σ interval when the old solver's failures count
   as flat (σ = ∞, as main did) and when they are refitted, both the order statistics
   at 0.025 and 0.975 of the same draws, beside fit_v50's own.

Prints figures, asserts nothing (tests/test_v50_order.py holds the promises). About
70 s on one core with the defaults.
"""

from __future__ import annotations

import argparse
import math
import time
from pathlib import Path

import numpy as np
from scipy import optimize, stats

from plateimpact.base.errors import V50Error
from plateimpact.storage.shots import Shots
from plateimpact.v50 import fit_v50
from plateimpact.v50.likelihood import LINKS, Estimate, GoNoGo, Link, check_shots, prepared
from plateimpact.v50.solver import maximum

DATA = Path(__file__).resolve().parents[1] / "tests" / "data" / "v50_weighted_13_rows.csv"


def old_maximum(shots: GoNoGo, link: Link, label: str) -> Estimate:
    """main@86344fb's plateimpact.v50.likelihood.maximum, verbatim but for names: scipy's
    trust-exact from (0, 1), refused unless |gradient| <= 1e-8 × the total weight."""
    design = np.column_stack([np.ones_like(shots.x), shots.x])

    def value(beta: np.ndarray) -> float:
        return shots.negative_log_likelihood(design @ beta, link)

    def gradient(beta: np.ndarray) -> np.ndarray:
        return design.T @ shots.eta_derivatives(design @ beta, link)[0]

    def hessian(beta: np.ndarray) -> np.ndarray:
        return (design.T * shots.eta_derivatives(design @ beta, link)[1]) @ design

    tolerance = 1e-8 * float(shots.weight.sum())
    found = optimize.minimize(
        value, np.array([0.0, 1.0]), jac=gradient, hess=hessian, method="trust-exact",
        options={"gtol": tolerance, "maxiter": 200},
    )  # fmt: skip
    if not (np.all(np.isfinite(found.x)) and np.abs(gradient(found.x)).max() <= tolerance):
        raise V50Error(f"{label}: the {link.name} fit did not converge: {found.message}")
    return Estimate(float(found.x[0]), float(found.x[1]), float(found.fun), int(found.nit))


def refused(solver: object, speed: np.ndarray, go: np.ndarray, weight: np.ndarray,
            link: Link) -> bool:  # fmt: skip
    try:
        solver(prepared(speed, go, weight), link, "shots")  # type: ignore[operator]
    except V50Error:
        return True
    return False


def orderings(args: argparse.Namespace) -> None:
    shots = Shots.from_csv(DATA)
    v, y, w = shots.impact_speed, shots.perforated, shots.weight
    rng = np.random.default_rng(args.seed)
    orders = [rng.permutation(v.size) for _ in range(args.orderings)]
    print(f"1. {DATA.name}: {v.size} rows, {w.sum():g} rounds, {len(orders)} row orders")
    for name, link in LINKS.items():
        before = sum(refused(old_maximum, v[o], y[o], w[o], link) for o in orders)
        after = sum(refused(maximum, v[o], y[o], w[o], link) for o in orders)
        fits = 0
        for o in orders:
            try:
                fit_v50(v[o], y[o], w[o], method=name, bootstrap=0)
            except V50Error:
                fits += 1
        print(f"   {name}: refused before {before}, after {after} (solver), {fits} (fit_v50)")


def random_sets(args: argparse.Namespace) -> None:
    rng = np.random.default_rng(args.seed)
    separated = 0
    counts = {name: [0, 0] for name in LINKS}
    for _ in range(args.sets):
        speed = rng.uniform(450.0, 550.0, 30)
        go = rng.random(30) < stats.norm.cdf((speed - 500.0) / 20.0)
        weight = np.ones(30)
        try:
            check_shots(speed, go, weight, "shots")
        except V50Error:
            separated += 1
            continue
        for name, link in LINKS.items():
            counts[name][0] += refused(old_maximum, speed, go, weight, link)
            counts[name][1] += refused(maximum, speed, go, weight, link)
    print(f"2. {args.sets} random sets of 30 shots: {separated} with no zone of mixed results "
          f"(refused by both); of the other {args.sets - separated}, refused for no "
          "convergence:")  # fmt: skip
    for name, (before, after) in counts.items():
        print(f"   {name}: before {before}, after {after}")


def resample_sigma(speed: np.ndarray, go: np.ndarray, weight: np.ndarray, link: Link,
                   solver: object) -> tuple[float, str]:  # fmt: skip
    """σ [m/s] of one resample and its kind, as plateimpact.v50.bootstrap reads it, with
    ``solver``; a solver's failure is ``failed`` (σ NaN)."""
    used = weight > 0
    up, down = used & go, used & ~go
    if up.any() and down.any():
        if speed[down].max() <= speed[up].min():
            return 0.0, "separated"
        if speed[up].max() > speed[down].min():
            shots = prepared(speed, go, weight)
            try:
                best = solver(shots, link, "resample")  # type: ignore[operator]
            except V50Error:
                return math.nan, "failed"
            if best.slope > 0:
                return shots.spread * best.scale * link.sigma_per_scale, "fitted"
    return math.inf, "flat"


def bootstrap(args: argparse.Namespace) -> None:
    shots = Shots.from_csv(DATA)
    link = LINKS["probit"]
    order = np.lexsort((shots.weight, shots.perforated, shots.impact_speed))  # fit_v50's
    v, w = shots.impact_speed[order], shots.weight[order]
    rows_v, rows_y = np.concatenate([v, v]), np.repeat([True, False], v.size)
    print(f"3. probit bootstrap of {DATA.name}, {args.resamples} resamples per seed; sigma "
          "95% interval [m/s] with the old solver's failures counted flat (before) and "
          "refitted (after), from the same draws:")  # fmt: skip
    for seed in range(args.seed, args.seed + args.bootstrap_seeds):
        fit = fit_v50(shots.impact_speed, shots.perforated, shots.weight,
                      bootstrap=args.resamples, rng=seed)  # fmt: skip
        p = stats.norm.cdf((v - fit.v50_m_s) / fit.scale_m_s)
        draws = np.random.default_rng(seed).binomial(
            w.astype(np.int64), p, (args.resamples, v.size)
        )
        found: dict[str, list[float]] = {"before": [], "after": []}
        failed = 0
        for count in draws:
            rows_w = np.concatenate([count, w - count]).astype(float)
            for when, solver in (("before", old_maximum), ("after", maximum)):
                sigma, kind = resample_sigma(rows_v, rows_y, rows_w, link, solver)
                if when == "before" and kind == "failed":
                    sigma, failed = math.inf, failed + 1  # what main did: flat
                found[when].append(sigma)
        ends = {when: np.quantile(values, [0.025, 0.975], method="inverted_cdf")
                for when, values in found.items()}  # fmt: skip
        print(f"   seed {seed}: {failed} resamples the old solver failed on; before "
              f"{fmt(tuple(ends['before']))}, after {fmt(tuple(ends['after']))}; fit_v50 now "
              f"{fmt(fit.sigma_bootstrap_ci_m_s)} (separated {fit.bootstrap_separated}, "
              f"flat {fit.bootstrap_flat}, failed {fit.bootstrap_failed})")  # fmt: skip


def fmt(interval: tuple[float | None, ...] | None) -> str:
    if interval is None:
        return "-"
    return "[" + ", ".join("unbounded" if x is None else f"{x:.4g}" for x in interval) + "]"


def main() -> None:
    parser = argparse.ArgumentParser(description=(__doc__ or "").splitlines()[0])
    parser.add_argument("--orderings", type=int, default=200)
    parser.add_argument("--sets", type=int, default=5000)
    parser.add_argument("--resamples", type=int, default=1000)
    parser.add_argument("--seed", type=int, default=0)
    parser.add_argument("--bootstrap-seeds", type=int, default=5, help="bootstraps in part 3")
    args = parser.parse_args()
    for part in (orderings, random_sets, bootstrap):
        start = time.perf_counter()
        part(args)
        print(f"   ({time.perf_counter() - start:.1f} s)")


if __name__ == "__main__":
    main()
