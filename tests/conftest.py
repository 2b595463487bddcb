from __future__ import annotations

import numpy as np
import pytest

import plateimpact as pi
from plateimpact import presets


@pytest.fixture(scope="session")
def sphere() -> pi.Sphere:
    return presets.DEFAULT_SPHERE


@pytest.fixture(scope="session")
def radius(sphere: pi.Sphere) -> float:
    return sphere.radius


def sweep(
    plate: str,
    speeds: np.ndarray,
    obliquity_deg: float,
    *,
    integrator: str = "dopri5",
    step: float = 2e-3,
    failure: str = "plugging",
    record_trajectory: bool = False,
) -> pi.BatchResult:
    """Results of one plate preset at one obliquity over ``speeds`` [m/s]; ``step`` is
    used by the segment integrator only."""
    settings = {"step": step} if integrator == "segment" else {}
    simulation = pi.Simulation.from_names(
        failure=failure, integrator=integrator, integrator_settings=settings
    )
    batch = pi.SceneBatch.grid(
        presets.DEFAULT_SPHERE,
        presets.plate(plate),
        speeds,
        [np.radians(obliquity_deg)],
    )
    return simulation.run_batch(batch, record_trajectory=record_trajectory)
