"""How often the V50 fit's confidence intervals hold the true V50 and σ.

python benchmarks/v50_coverage.py [--repetitions 100] [--shots 20,30] [--bootstrap 1000]
    [--design uniform|up-down|both] [--method probit] [--confidence 0.95] [--seed 0]

Each repetition fires go/no-go shots (20 and 30 by default) at a known probit curve
(V50 = 500 m/s, σ = 20 m/s: each shot perforates with probability Φ((v − V50)/σ)), at
speeds of one of two designs: ``uniform`` in V50 ± 2.5 σ, or ``up-down`` (from a guess
of V50, a step of σ/2 down after each perforation and up after each non-perforation, as
V50 firings are done). It fits them (plateimpact.v50.fit_v50) and asks whether each
interval, profile likelihood and bootstrap, holds the true V50 and σ. A repetition the
fit refuses (no zone of mixed results) counts as not covered. Prints the coverage of
each interval with its binomial standard error, the median widths, and the refusals.
The repetitions are seeded: the same arguments print the same numbers (about 3 minutes
with the defaults on one core).
"""

from __future__ import annotations

import argparse
import time

import numpy as np
from scipy import stats

from plateimpact.base.errors import V50Error
from plateimpact.v50 import fit_v50

TRUE_V50, TRUE_SIGMA = 500.0, 20.0  # [m/s]
#: Shot speeds are drawn from V50 ± this many σ.
SPEED_HALF_WIDTH = 2.5
#: The up-and-down design's step, in σ.
UP_DOWN_STEP = 0.5


def perforates(rng: np.random.Generator, speed: np.ndarray | float) -> np.ndarray:
    """Go/no-go at ``speed`` [m/s], drawn from the known probit curve."""
    return np.asarray(rng.random(np.shape(speed)) < stats.norm.cdf((speed - TRUE_V50) / TRUE_SIGMA))


def uniform_shots(rng: np.random.Generator, count: int) -> tuple[np.ndarray, np.ndarray]:
    """``count`` shots at speeds [m/s] uniform in V50 ± SPEED_HALF_WIDTH σ."""
    reach = SPEED_HALF_WIDTH * TRUE_SIGMA
    speed = rng.uniform(TRUE_V50 - reach, TRUE_V50 + reach, count)
    return speed, perforates(rng, speed)


def up_down_shots(rng: np.random.Generator, count: int) -> tuple[np.ndarray, np.ndarray]:
    """``count`` shots fired up and down: the first at a guess of V50 (the truth ± σ),
    each next one a step of UP_DOWN_STEP σ slower after a perforation, faster after none
    (the field's way of placing shots near V50, as MIL-STD-662F does)."""
    speed = np.empty(count)
    perforated = np.empty(count, dtype=bool)
    speed[0] = TRUE_V50 + TRUE_SIGMA * rng.standard_normal()
    for i in range(count):
        perforated[i] = perforates(rng, speed[i])
        if i + 1 < count:
            speed[i + 1] = speed[i] + (-1 if perforated[i] else 1) * UP_DOWN_STEP * TRUE_SIGMA
    return speed, perforated


DESIGNS = {"uniform": uniform_shots, "up-down": up_down_shots}


def holds(interval: tuple[float | None, float | None] | None, truth: float) -> bool:
    """Whether ``interval`` holds ``truth`` (an end None is unbounded)."""
    if interval is None:
        return False
    low, high = interval
    return (low is None or low <= truth) and (high is None or truth <= high)


def width(interval: tuple[float | None, float | None] | None) -> float:
    if interval is None or None in interval:
        return np.inf
    return float(interval[1] - interval[0])  # type: ignore[operator]


def coverage(args: argparse.Namespace, design: str, count: int) -> None:
    """Run the repetitions of one design and shot count; print one block."""
    rng = np.random.default_rng(args.seed)
    names = ("v50_ci_m_s", "sigma_ci_m_s", "v50_bootstrap_ci_m_s", "sigma_bootstrap_ci_m_s")
    covered = {name: 0 for name in names}
    widths: dict[str, list[float]] = {name: [] for name in names}
    refused = 0
    start = time.perf_counter()
    for _ in range(args.repetitions):
        speed, perforated = DESIGNS[design](rng, count)
        try:
            fit = fit_v50(
                speed, perforated, method=args.method, confidence=args.confidence,
                bootstrap=args.bootstrap, rng=rng,
            )  # fmt: skip
        except V50Error:
            refused += 1
            continue
        for name in names:
            truth = TRUE_V50 if name.startswith("v50") else TRUE_SIGMA
            covered[name] += holds(getattr(fit, name), truth)
            widths[name].append(width(getattr(fit, name)))
    n, fitted = args.repetitions, args.repetitions - refused
    print(
        f"{design}, {count} shots: {refused} of {n} refused (no zone of mixed results: "
        f"counted as not covered); {time.perf_counter() - start:.1f} s"
    )
    for name in names:
        share = covered[name] / n
        error = np.sqrt(share * (1 - share) / n)
        print(
            f"  {name:24s} holds the truth in {covered[name]:3d} of {n} "
            f"({100 * share:.0f} +- {100 * error:.0f} %; {covered[name]} of the {fitted} "
            f"fitted), median width {np.median(widths[name]) if widths[name] else np.nan:.1f} m/s"
        )


def main() -> None:
    parser = argparse.ArgumentParser(description=(__doc__ or "").splitlines()[0])
    parser.add_argument("--repetitions", type=int, default=100)
    parser.add_argument("--shots", default="20,30", help="shot counts, a comma list")
    parser.add_argument("--design", choices=[*DESIGNS, "both"], default="both")
    parser.add_argument("--bootstrap", type=int, default=1000)
    parser.add_argument("--method", default="probit")
    parser.add_argument("--confidence", type=float, default=0.95)
    parser.add_argument("--seed", type=int, default=0)
    args = parser.parse_args()
    print(
        f"{args.repetitions} repetitions per row, go/no-go shots from a probit curve "
        f"(V50 {TRUE_V50:g} m/s, sigma {TRUE_SIGMA:g} m/s); {args.method} fits, "
        f"{args.confidence:g} intervals, {args.bootstrap} bootstrap resamples, seed {args.seed}"
    )
    designs = list(DESIGNS) if args.design == "both" else [args.design]
    for design in designs:
        for count in (int(x) for x in args.shots.split(",")):
            coverage(args, design, count)


if __name__ == "__main__":
    main()
