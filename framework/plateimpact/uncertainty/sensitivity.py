"""Sobol' sensitivity indices: which uncertain input the spread of a result comes from.

First-order (S1: the share of the variance that one input explains alone) and total
(ST: with all its interactions) indices by Saltelli's sampling and the Jansen/Saltelli
estimators of SALib, with bootstrap confidence intervals. The points are drawn in the
unit cube and mapped through each input's distribution (the same ``ppf`` as propagation),
so any distribution of :mod:`.distributions` can be analysed. The quantity is any
function of the sampled inputs: a test function (Ishigami, tests), whether each sample
perforates (whose variance is P(1 − P)), or each sample's ballistic limit."""

from __future__ import annotations

from collections.abc import Callable
from concurrent.futures import Executor
from typing import Any

import attrs
import numpy as np

from ..base.extras import SOBOL, optional
from ..model.results import Outcome
from ..registry.plugin_registry import PluginRegistry
from ..run.simulation import Simulation
from .distributions import Distribution
from .limit_search import RESOLUTION, SPEEDS, TOLERANCE, line_limits, sample_scenes
from .propagation import EDGE, scenes
from .spec import UncertaintySpec, UncertaintySpecError

Quantity = Callable[[dict[str, np.ndarray]], np.ndarray]


@attrs.frozen
class SobolIndices:
    """First-order and total indices of each input, with the half-widths of their
    ``confidence`` intervals (bootstrap), from ``evaluations`` runs of the quantity."""

    names: tuple[str, ...]
    first: np.ndarray
    first_halfwidth: np.ndarray
    total: np.ndarray
    total_halfwidth: np.ndarray
    evaluations: int
    confidence: float

    def dominant(self) -> str:
        """The input with the largest total index."""
        return self.names[int(np.argmax(self.total))]

    def to_json(self) -> dict[str, Any]:
        return {
            "evaluations": self.evaluations,
            "confidence": self.confidence,
            "dominant": self.dominant(),
            "indices": {
                name: {
                    "first": float(self.first[i]),
                    "first_interval": [
                        float(self.first[i] - self.first_halfwidth[i]),
                        float(self.first[i] + self.first_halfwidth[i]),
                    ],
                    "total": float(self.total[i]),
                    "total_interval": [
                        float(self.total[i] - self.total_halfwidth[i]),
                        float(self.total[i] + self.total_halfwidth[i]),
                    ],
                }
                for i, name in enumerate(self.names)
            },
        }


def sobol_indices(
    distributions: dict[str, Distribution],
    quantity: Quantity,
    base_samples: int,
    seed: int,
    *,
    confidence: float = 0.95,
    resamples: int = 200,
) -> SobolIndices:
    """S1 and ST of ``quantity`` (a function of the inputs' values, by name, one per
    point) to each of ``distributions``, from ``base_samples`` × (inputs + 2) points
    (Saltelli's scheme; ``base_samples`` a power of 2 keeps the Sobol' points balanced)."""
    optional("SALib", "sobol_indices", SOBOL)  # before any point runs
    from SALib.analyze import sobol as analyze  # noqa: PLC0415 (a heavy import)
    from SALib.sample import sobol as sample  # noqa: PLC0415

    names = tuple(distributions)
    problem = {"num_vars": len(names), "names": list(names), "bounds": [[0.0, 1.0]] * len(names)}
    points = sample.sample(problem, base_samples, calc_second_order=False, seed=seed)
    points = np.clip(points, EDGE, 1.0 - EDGE)
    values = {name: distributions[name].ppf(points[:, j]) for j, name in enumerate(names)}
    y = np.asarray(quantity(values), float)
    found = analyze.analyze(
        problem,
        y,
        calc_second_order=False,
        conf_level=confidence,
        num_resamples=resamples,
        seed=seed,
    )
    return SobolIndices(
        names,
        np.asarray(found["S1"]),
        np.asarray(found["S1_conf"]),
        np.asarray(found["ST"]),
        np.asarray(found["ST_conf"]),
        int(y.size),
        confidence,
    )


def _independent(spec: UncertaintySpec) -> None:
    if spec.correlations:
        raise UncertaintySpecError(
            f"{spec.source}: correlations: Sobol' indices need independent inputs"
        )


def perforation_indices(
    spec: UncertaintySpec,
    registry: PluginRegistry,
    base_samples: int,
    *,
    simulation: Simulation | None = None,
    executor: Executor | None = None,
    confidence: float = 0.95,
) -> SobolIndices:
    """Sobol' indices of whether a sample perforates (its mean is P(perforation)) at the
    spec's condition, to each of the spec's uncertain inputs (``executor``: where the
    batch runs, in chunks, with the same bits), with bootstrap intervals at
    ``confidence``."""
    _independent(spec)
    if simulation is None:
        simulation = Simulation.from_names(failure=spec.failure, registry=registry)
    run = simulation

    def perforates(values: dict[str, np.ndarray]) -> np.ndarray:
        n = next(iter(values.values())).size
        batch = scenes(attrs.evolve(spec, samples=n), values, registry)
        outcome = run.run_batch(batch, executor=executor).outcome
        return (outcome == Outcome.PERFORATION).astype(float)

    return sobol_indices(
        dict(spec.inputs), perforates, base_samples, spec.seed, confidence=confidence
    )


def ballistic_limit_indices(
    spec: UncertaintySpec,
    registry: PluginRegistry,
    base_samples: int,
    *,
    speeds: tuple[float, float] = SPEEDS,
    tolerance: float = TOLERANCE,
    resolution: float = RESOLUTION,
    simulation: Simulation | None = None,
    executor: Executor | None = None,
    confidence: float = 0.95,
) -> SobolIndices:
    """Sobol' indices of the ballistic limit [m/s] (each Saltelli point's, found by the
    limits finder over ``speeds`` at the spec's obliquity, or at the point's own where
    the obliquity is uncertain) to each of the spec's uncertain inputs. The speed takes
    no distribution (the limit is a speed); a point whose limit is outside the range is
    refused, naming how many (an index of a quantity that is not a number is none)."""
    if "speed_m_s" in spec.inputs:
        raise UncertaintySpecError(
            f"{spec.source}: inputs.speed_m_s: the ballistic limit is a speed: its Sobol' "
            "indices take the speed without a distribution (give it in at, or leave it out)"
        )
    _independent(spec)
    if simulation is None:
        simulation = Simulation.from_names(failure=spec.failure, registry=registry)
    run = simulation

    def limits(values: dict[str, np.ndarray]) -> np.ndarray:
        base = sample_scenes(spec, values, registry, speeds)
        found = line_limits(
            base, np.arange(base.size), base.columns["impact_obliquity"], run,
            speeds=speeds, tolerance=tolerance, resolution=resolution, executor=executor,
        )  # fmt: skip
        outside = int(np.sum(~np.isfinite(found.ballistic)))
        if outside:
            raise UncertaintySpecError(
                f"{spec.source}: {outside:,} of {base.size:,} Saltelli points have no "
                f"ballistic limit in {speeds[0]:g}-{speeds[1]:g} m/s (they perforate at "
                "every speed of it or at none): narrow the inputs' distributions"
            )
        return found.ballistic

    return sobol_indices(dict(spec.inputs), limits, base_samples, spec.seed, confidence=confidence)
