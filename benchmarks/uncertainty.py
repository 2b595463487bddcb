"""Uncertainty propagation: its speed, and how its error falls with the number of samples.

  * 10^5 samples of one (speed, obliquity) condition (speed normal, P* uniform; the
    docs/uncertainty.md example), by each method, wall time in this process (the
    compiled path on every core);
  * 2,000 sampled limits at 30 and at 60 deg (P* uniform, a normal): the ballistic and
    the ricochet limit of every sample come out of one search, wall time; then the whole
    V0-V100 curves P(perforation | V) and P(ricochet | V) at 1,000 speeds, with their
    intervals and V10/V50/V90, from those limits; and both obliquities in one search;
  * convergence: P(perforation) at normal incidence on 2024-T3/3.18 (plugging) with only
    the speed uncertain (normal, σ = 20 m/s, μ = V_bl + 0.3σ), whose exact value is
    1 − Φ((V_bl − μ)/σ) for the closed-form ballistic limit V_bl; the root-mean-square
    error over 16 seeds at N = 2^6 ... 2^12, Monte Carlo against scrambled Sobol', and the
    slope of log error against log N (Monte Carlo: −1/2).

Writes benchmarks/results/uncertainty_convergence.png.

Run:  python benchmarks/uncertainty.py
"""

from __future__ import annotations

import math
import sys
import time
from pathlib import Path

import numpy as np
from scipy import stats

import plateimpact as pi
from plateimpact import presets
from plateimpact.figures import saving, style
from plateimpact.model.impact import REST_SPEED_FRACTION
from plateimpact.uncertainty import propagate, read_spec
from plateimpact.uncertainty.limits import sampled_limits, sampled_limits_at

RESULTS = Path(__file__).resolve().parent / "results"
# the closed form the tests check the model against (tests/closed_forms.py)
sys.path.insert(0, str(Path(__file__).resolve().parents[1] / "tests"))
from closed_forms import ballistic_limit  # noqa: E402

PRESET = "2024-T3/3.18"
EXAMPLE = {
    "preset": PRESET,
    "failure": "plugging",
    "at": {"speed_m_s": 400, "obliquity_deg": 0},
    "inputs": {
        "speed_m_s": {"normal": {"mean": 400, "sd": 15}},
        "pstar_mm": {"uniform": {"low": 2.5, "high": 3.5}},
    },
    "seed": 7,
}


def timings(registry: pi.PluginRegistry) -> None:
    propagate(read_spec({**EXAMPLE, "samples": 1000}, registry), registry)  # warm-up
    for method in ("mc", "sobol", "lhs"):
        spec = read_spec({**EXAMPLE, "samples": 100_000, "method": method}, registry)
        start = time.perf_counter()
        found = propagate(spec, registry)
        took = time.perf_counter() - start
        low, high = found.intervals()["perforation"]
        print(
            f"10^5 samples, {method:5s}: {took:.2f} s; P(perforation) "
            f"{found.probabilities()['perforation']:.4f} [{low:.4f}, {high:.4f}]"
        )
    limits_spec = {
        "preset": PRESET,
        "failure": "plugging",
        "at": {"obliquity_deg": 30},
        "inputs": {
            "pstar_mm": {"uniform": {"low": 2.5, "high": 3.5}},
            "a_N_m2": {"normal": {"mean": 1.01e9, "sd": 5e7}},
        },
        "samples": 2000,
        "seed": 2,
    }
    spec = read_spec(limits_spec, registry)
    for obliquity in (30.0, 60.0):
        start = time.perf_counter()
        limits = sampled_limits(spec, registry, obliquity)
        searched = time.perf_counter() - start
        # the whole V0-V100 curve from those limits: 1,000 speeds from the lowest limit
        # to the highest, each with its exact binomial interval, and V10/V50/V90
        start = time.perf_counter()
        speeds = np.linspace(limits.ballistic.min(), limits.ballistic.max(), 1000)
        limits.perforation_curve(speeds)
        limits.ricochet_curve(speeds)
        report = {name: limits.report(name) for name in ("ballistic", "ricochet")}
        curve = time.perf_counter() - start
        print(
            f"2,000 sampled limits at {obliquity:g} deg, ballistic and ricochet in one search: "
            f"{searched:.1f} s ({limits.scenes:,} scenes, {limits.passes} passes); the "
            f"V0-V100 curves at 1,000 speeds and the quantiles from them: {curve:.2f} s; "
            f"V50 {report['ballistic']['v50_m_s']:.1f} m/s (ballistic), "
            f"{report['ricochet']['v50_m_s']:.1f} m/s (ricochet)"
        )
    start = time.perf_counter()
    both = sampled_limits_at(spec, registry, [30.0, 60.0])
    took = time.perf_counter() - start
    print(f"the same at 30 and 60 deg in one search: {took:.1f} s ({both[0].scenes:,} scenes)")


def convergence(registry: pi.PluginRegistry) -> None:
    plate, sphere = presets.plate(PRESET), presets.DEFAULT_SPHERE
    limit, sd = ballistic_limit(plate, sphere, REST_SPEED_FRACTION.default), 20.0
    mean = limit + 0.3 * sd
    exact = 1.0 - stats.norm.cdf((limit - mean) / sd)
    sizes = 2 ** np.arange(6, 13)
    errors = {"mc": [], "sobol": []}
    for method in errors:
        for n in sizes:
            squared = []
            for seed in range(16):
                spec = read_spec(
                    {
                        "preset": PRESET,
                        "failure": "plugging",
                        "at": {"obliquity_deg": 0.0},
                        "inputs": {"speed_m_s": {"normal": {"mean": mean, "sd": sd}}},
                        "samples": int(n),
                        "method": method,
                        "seed": 1000 + seed,
                    },
                    registry,
                )
                p = propagate(spec, registry).probabilities()["perforation"]
                squared.append((p - exact) ** 2)
            errors[method].append(math.sqrt(np.mean(squared)))
    print(f"convergence: exact P(perforation) {exact:.6f} (V_bl {limit:.3f} m/s)")
    print("      N  " + "  ".join(f"{m:>10s}" for m in errors))
    for i, n in enumerate(sizes):
        print(f"{n:7d}  " + "  ".join(f"{errors[m][i]:10.2e}" for m in errors))
    slopes = {m: np.polyfit(np.log(sizes), np.log(errors[m]), 1)[0] for m in errors}
    print("slopes: " + ", ".join(f"{m} {s:.2f}" for m, s in slopes.items()))
    fig, ax = style.figure(figsize=(style.COLUMN_WIDTH, 2.6), layout="constrained")
    for method, label in (("mc", "Monte Carlo"), ("sobol", "scrambled Sobol'")):
        ax.loglog(sizes, errors[method], "o-", label=f"{label} (slope {slopes[method]:.2f})")
    ax.loglog(sizes, errors["mc"][0] * np.sqrt(sizes[0] / sizes), ":", color="0.5",
              label="N^-1/2")  # fmt: skip
    ax.set_xlabel("samples N")
    ax.set_ylabel("RMS error of P(perforation)")
    ax.legend(fontsize=style.SMALL)
    RESULTS.mkdir(exist_ok=True)
    saving.save(fig, str(RESULTS / "uncertainty_convergence.png"))
    print(f"wrote {RESULTS / 'uncertainty_convergence.png'}")


def main() -> None:
    registry = pi.default_registry()
    if "--convergence-only" not in sys.argv:
        timings(registry)
    convergence(registry)


if __name__ == "__main__":
    main()
