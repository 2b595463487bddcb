"""Uncertainty propagation: its speed, and how its error falls with the number of samples.

  * 10^5 samples of one (speed, obliquity) condition (speed normal, P* uniform; the
    docs/uncertainty.md example), by each method, wall time in this process (the
    compiled path on every core);
  * 2,000 sampled ballistic limits at one obliquity (P* uniform, a normal), wall time;
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
from plateimpact.uncertainty.limits import sampled_limits

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
    start = time.perf_counter()
    limits = sampled_limits(read_spec(limits_spec, registry), registry, 30.0)
    took = time.perf_counter() - start
    v50 = limits.quantile(0.5)
    print(f"2,000 sampled ballistic limits at 30 deg: {took:.1f} s; V50 {v50['speed_m_s']:.1f} m/s")


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
