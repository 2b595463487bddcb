"""The fixed, seeded benchmark scenes shared by the benchmark scripts."""

from __future__ import annotations

import numpy as np

import plateimpact as pi
from plateimpact import presets


def benchmark_batch(size: int, seed: int = 5844) -> pi.SceneBatch:
    """``size`` scenes: the five presets in turn, obliquity uniform in 0–70°, impact speed
    uniform in 50–1500 m/s, the default sphere."""
    rng = np.random.default_rng(seed)
    names = list(presets.PLATES)
    parts = []
    for k, name in enumerate(names):
        count = size // len(names) + (1 if k < size % len(names) else 0)
        part = pi.SceneBatch.grid(
            presets.DEFAULT_SPHERE, presets.plate(name), np.full(count, 100.0), [0.0]
        )
        parts.append(
            part.with_columns(
                impact_speed=rng.uniform(50.0, 1500.0, count),
                impact_obliquity=np.radians(rng.uniform(0.0, 70.0, count)),
            )
        )
    return pi.SceneBatch.concat(parts)
