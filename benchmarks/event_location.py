"""How many margin evaluations the driver's event root finding takes.

1. A cubic dense output, y(σ) = σ + 0.3σ² − 0.2σ³, and 200 levels: the evaluations
   Illinois needs, with an exact margin and with one that wiggles by 1e-12 around its
   root (a difference of larger lengths at rounding);
2. the loops of a real sweep: iterations per root-finding loop on the benchmark scenes.

Run:  python benchmarks/event_location.py
"""

from __future__ import annotations

import numpy as np
from scenes import benchmark_batch

import plateimpact as pi
from plateimpact.solve import events


def cubic(blur: float) -> int:
    levels = np.random.default_rng(1).uniform(0.05, 1.0, 200)
    coefficients = np.zeros((3, 1, levels.size))
    coefficients[:, 0] = np.array([1.0, 0.3, -0.2])[:, np.newaxis]
    dense = pi.PolynomialDenseOutput(np.zeros((1, levels.size)), coefficients)
    calls = []

    def margin(state: np.ndarray) -> np.ndarray:
        calls.append(1)
        return (state[0] - levels) + blur * np.sin(1e12 * state[0])

    samples = np.linspace(0.0, 1.0, 5)
    path = samples + 0.3 * samples**2 - 0.2 * samples**3
    first = np.argmax((path[:-1, None] < levels) & (path[1:, None] >= levels), axis=0)
    lo, hi = samples[first], samples[first + 1]
    f_lo, f_hi = margin(dense(lo)), margin(dense(hi))
    calls.clear()
    events.locate(margin, dense, lo, hi, f_lo, f_hi)
    return len(calls)


def main() -> None:
    for blur in (0.0, 1e-12):
        print(
            f"cubic dense output, margin wiggle {blur:g}: {cubic(blur)} evaluations for 200 roots"
        )
    loops = []
    original = events.locate

    def counting(margin, dense, lo, hi, f_lo, f_hi):  # type: ignore[no-untyped-def]
        count = [0]

        def counted(state: np.ndarray) -> np.ndarray:
            count[0] += 1
            return margin(state)

        found = original(counted, dense, lo, hi, f_lo, f_hi)
        loops.append(count[0])
        return found

    events.locate = counting
    try:
        pi.Simulation.from_names().run_batch(benchmark_batch(5000, seed=10_000))
    finally:
        events.locate = original
    print(
        f"5,000-scene sweep: {len(loops)} root-finding loops, {np.mean(loops):.1f} iterations "
        f"per loop (most {max(loops)})"
    )


if __name__ == "__main__":
    main()
