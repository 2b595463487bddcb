"""Shots made by the model itself, with a stated noise model: for testing fits and
scores against known constants, never as a substitute for firings."""

from __future__ import annotations

import math
from collections.abc import Sequence

import numpy as np

from ..base.errors import ParameterError
from ..model.batch import SceneBatch
from ..model.bodies import Plate, Sphere
from ..model.results import Outcome
from ..model.scene import IMPACT_SPEED
from ..run.simulation import Simulation
from ..storage.shots import Shots


def synthetic_shots(
    plate: Plate,
    sphere: Sphere,
    impact_speeds: Sequence[float] | np.ndarray,
    *,
    noise: float = 0.0,
    seed: int | None = None,
    simulation: Simulation | None = None,
) -> Shots:
    """Shots at normal incidence made by the model itself, with optional noise.

    The residual speeds are the model's for ``plate`` and ``sphere`` at
    ``impact_speeds`` [m/s] (one batch), each multiplied by ``1 + noise * N(0, 1)``
    (``noise`` is the relative standard deviation, e.g. 0.02; a perforation stays a
    perforation: the factor is kept above 0.1).
    """
    speeds = np.asarray(impact_speeds, dtype=float).reshape(-1)
    simulation = simulation or Simulation.from_names()
    result = simulation.run_batch(SceneBatch.grid(sphere, plate, speeds, np.zeros(1)))
    factor = 1.0 + noise * np.random.default_rng(seed).standard_normal(speeds.size)
    residual = result.exit_speed * np.maximum(factor, 0.1)
    perforated = result.outcome == Outcome.PERFORATION
    return Shots(
        impact_speed=speeds,
        impact_obliquity=np.zeros(speeds.size),
        residual_speed=np.where(perforated, np.minimum(residual, speeds), 0.0),
        exit_obliquity=np.where(perforated, result.exit_obliquity, np.nan),
        outcome=result.outcome.astype(int),
        labels=tuple(f"synthetic shot {i}" for i in range(speeds.size)),
        source="synthetic shots",
    )


def synthetic_oblique_shots(
    simulation: Simulation,
    sphere: Sphere,
    plate: Plate,
    impact_speeds: Sequence[float] | np.ndarray,
    impact_obliquities: Sequence[float] | np.ndarray,
    rng: np.random.Generator | None = None,
    *,
    speed_noise: float = 0.0,
    residual_noise: float = 0.0,
    exit_obliquity_noise: float = 0.0,
    go_no_go_fraction: float = 0.0,
) -> Shots:
    """Oblique shots made by the model, as a test range would record them.

    One shot per pair of ``impact_speeds`` [m/s] and ``impact_obliquities`` [rad] (the
    true impacts; the two broadcast against each other). The outcome is the model's at
    the true impact, as in a firing; what is recorded has noise, drawn from ``rng``:

    * impact speed: true + ``speed_noise`` [m/s] × N(0, 1) (kept >= 1 mm/s);
    * residual speed (perforation and ricochet; 0 for embedment): the model's exit
      speed × (1 + ``residual_noise`` × N(0, 1)), the factor kept above 0.1 and the
      speed at most the recorded impact speed;
    * exit obliquity (perforation and ricochet): the model's + ``exit_obliquity_noise``
      [rad] × N(0, 1), kept in [0, π];
    * each shot, with probability ``go_no_go_fraction``, records only whether it
      perforated (outcome 0, no residual speed or exit obliquity).

    With no noise the shots are the model's own results, to the last bit.
    """
    true_speed, obliquity = (
        np.asarray(x, dtype=float).ravel()
        for x in np.broadcast_arrays(np.asarray(impact_speeds), np.asarray(impact_obliquities))
    )
    for name, value in (
        ("speed_noise", speed_noise),
        ("residual_noise", residual_noise),
        ("exit_obliquity_noise", exit_obliquity_noise),
    ):
        if not (math.isfinite(value) and value >= 0.0):
            raise ParameterError(name, f"{name} must be finite and >= 0, got {value!r}")
    if not 0.0 <= go_no_go_fraction <= 1.0:
        raise ParameterError(
            "go_no_go_fraction", f"go_no_go_fraction must be in [0, 1], got {go_no_go_fraction!r}"
        )
    rng = rng if rng is not None else np.random.default_rng()
    n = true_speed.size
    labels = tuple(f"synthetic shot {i}" for i in range(n))
    truth = Shots(
        true_speed, obliquity, np.full(n, np.nan), np.full(n, np.nan), np.zeros(n, int), labels
    )
    result = simulation.run_batch(truth.scenes(sphere, plate))
    outcome = result.outcome.astype(int)
    exits = outcome != Outcome.EMBEDMENT
    speed = np.maximum(true_speed + speed_noise * rng.standard_normal(n), IMPACT_SPEED.range.low)
    factor = np.maximum(1.0 + residual_noise * rng.standard_normal(n), 0.1)
    residual = np.where(exits, np.minimum(result.exit_speed * factor, speed), 0.0)
    exit_obliquity = result.exit_obliquity + exit_obliquity_noise * rng.standard_normal(n)
    exit_obliquity = np.where(exits, np.clip(exit_obliquity, 0.0, math.pi), np.nan)
    go_no_go = rng.random(n) < go_no_go_fraction
    return Shots(
        impact_speed=speed,
        impact_obliquity=obliquity,
        residual_speed=np.where(go_no_go, np.nan, residual),
        exit_obliquity=np.where(go_no_go, np.nan, exit_obliquity),
        outcome=np.where(go_no_go, 0, outcome),
        labels=labels,
        source="synthetic shots",
        perforated=outcome == Outcome.PERFORATION,
    )
