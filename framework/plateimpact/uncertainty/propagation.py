"""Propagation by direct simulation: the spec's inputs sampled (independent draws,
scrambled Sobol' or Latin hypercube points of ``scipy.stats.qmc``, mapped through each
distribution's inverse), one scene per sample run as one batch through the normal
simulation, and the probability of each outcome with its exact (Clopper–Pearson)
binomial interval."""

from __future__ import annotations

import hashlib
import json
import os
import warnings
from concurrent.futures import Executor
from pathlib import Path
from typing import Any

import attrs
import numpy as np
from scipy import stats
from scipy.stats import qmc

from ..model.batch import SceneBatch
from ..model.results import BatchResult, Outcome
from ..registry.plugin_registry import PluginRegistry
from ..run.simulation import Simulation
from .inputs import input_table
from .spec import UncertaintySpec, UncertaintySpecError, correlation_matrix

#: The outcomes whose probabilities are reported, by their names in outputs.
OUTCOMES = {"ricochet": Outcome.RICOCHET, "embedment": Outcome.EMBEDMENT,
            "perforation": Outcome.PERFORATION}  # fmt: skip
#: Unit samples are kept this far inside (0, 1): the inverse of a normal is infinite at
#: 0 and 1 (a scrambled Sobol' point can be 0).
EDGE = 2.0**-53


def unit_samples(method: str, count: int, dimensions: int, seed: int) -> np.ndarray:
    """``count`` points in [0, 1)^``dimensions`` by ``method`` ("mc", "sobol", "lhs"),
    from ``seed``: the same points for the same arguments, on every machine."""
    rng = np.random.default_rng(seed)
    if dimensions == 0:
        return np.empty((count, 0))
    if method == "mc":
        return rng.random((count, dimensions))
    if method == "sobol":
        with warnings.catch_warnings():  # a count not a power of 2 loses some balance
            warnings.simplefilter("ignore", UserWarning)
            return qmc.Sobol(dimensions, scramble=True, seed=rng).random(count)
    return qmc.LatinHypercube(dimensions, seed=rng).random(count)


@attrs.frozen
class Propagation:
    """A propagated spec: the sampled inputs [user units, by name], the batch's result,
    and the confidence of the intervals."""

    spec: UncertaintySpec
    inputs: dict[str, np.ndarray]
    result: BatchResult
    confidence: float = 0.95

    @property
    def counts(self) -> dict[str, int]:
        """How many samples ended in each outcome."""
        return {name: int(np.sum(self.result.outcome == code)) for name, code in OUTCOMES.items()}

    def probabilities(self) -> dict[str, float]:
        """The fraction of samples ending in each outcome."""
        n = self.result.outcome.size
        return {name: count / n for name, count in self.counts.items()}

    def intervals(self) -> dict[str, tuple[float, float]]:
        """Each probability's exact binomial interval at :attr:`confidence` (for Sobol'
        and Latin hypercube points, conservative: they vary less than independent
        draws)."""
        n = self.result.outcome.size
        out = {}
        for name, count in self.counts.items():
            low, high = binomial_intervals(np.array(count), n, self.confidence)
            out[name] = (float(low), float(high))
        return out

    def exit_quantiles(self, levels: tuple[float, ...] = (0.05, 0.5, 0.95)) -> dict[str, Any]:
        """Quantiles of the exit speed [m/s] of the perforations and of the exit
        obliquity [deg] of the ricochets (None where there are none)."""
        result = self.result
        perforated = result.outcome == Outcome.PERFORATION
        ricocheted = result.outcome == Outcome.RICOCHET
        speed = result.exit_speed[perforated]
        angle = np.degrees(result.exit_obliquity[ricocheted])
        return {
            "levels": list(levels),
            "perforation_exit_speed_m_s": np.quantile(speed, levels).tolist()
            if speed.size
            else None,
            "ricochet_exit_obliquity_deg": np.quantile(angle, levels).tolist()
            if angle.size
            else None,
        }

    def to_json(self) -> dict[str, Any]:
        """The summary as JSON-ready values, with what produced it."""
        return {
            "samples": int(self.result.outcome.size),
            "method": self.spec.method,
            "seed": self.spec.seed,
            "confidence": self.confidence,
            "probabilities": self.probabilities(),
            "intervals": {k: list(v) for k, v in self.intervals().items()},
            "counts": self.counts,
            "exit_quantiles": self.exit_quantiles(),
            "spec": self.spec.describe(),
        }


def binomial_intervals(
    counts: np.ndarray, n: int, confidence: float
) -> tuple[np.ndarray, np.ndarray]:
    """The exact (Clopper–Pearson) interval of each proportion ``counts`` / ``n`` at
    ``confidence``: arrays (low, high) of ``counts``' shape. Its ends are the quantiles
    of beta distributions, P(X >= k) = I_p(k, n − k + 1) and P(X <= k) = 1 − I_p(k + 1,
    n − k), all at once: the interval ``scipy.stats.binomtest`` finds one root at a time
    (the same to 1e-12, tested), a thousand times faster for a curve."""
    k = np.asarray(counts)
    tail = (1.0 - confidence) / 2.0
    with np.errstate(divide="ignore", invalid="ignore"):  # k = 0 or n: ends fixed below
        low = np.where(k == 0, 0.0, stats.beta.ppf(tail, k, n - k + 1))
        high = np.where(k == n, 1.0, stats.beta.isf(tail, k + 1, n - k))
    return np.asarray(low, float), np.asarray(high, float)


def sample_inputs(spec: UncertaintySpec) -> dict[str, np.ndarray]:
    """Each uncertain input's values [its user unit], one per sample, in the spec's order
    of inputs (their columns of the unit points)."""
    names = list(spec.inputs)
    points = unit_samples(spec.method, spec.samples, len(names), spec.seed)
    points = np.clip(points, EDGE, 1.0 - EDGE)
    if spec.correlations:
        # A Gaussian copula: the points' normal scores correlated by the matrix's Cholesky
        # factor, back to probabilities (the inputs' normal scores then have these
        # correlations: the Pearson correlations of normal inputs).
        factor = np.linalg.cholesky(correlation_matrix(spec.correlations, names))
        scores = stats.norm.ppf(points) @ factor.T
        points = np.clip(stats.norm.cdf(scores), EDGE, 1.0 - EDGE)
    return {name: spec.inputs[name].ppf(points[:, j]) for j, name in enumerate(names)}


def scenes(
    spec: UncertaintySpec, inputs: dict[str, np.ndarray], registry: PluginRegistry
) -> SceneBatch:
    """One scene per sample: the preset's sphere and plate at the spec's ``at``, with
    each uncertain input's sampled values (checked against its range by the batch)."""
    table = input_table(registry)
    n = spec.samples
    nominal = {}
    for name in ("speed_m_s", "obliquity_deg"):
        value = spec.at[name] if name in spec.at else float(inputs[name][0])
        nominal[name] = value * table[name].parameter.scale
    batch = SceneBatch.grid(
        registry.sphere,
        spec.plate,
        np.full(n, nominal["speed_m_s"]),
        [nominal["obliquity_deg"]],
    )
    columns = {
        table[name].column: np.full(n, value * table[name].parameter.scale)
        for name, value in spec.at.items()
        if name not in ("speed_m_s", "obliquity_deg")
    }
    for name, values in inputs.items():
        columns[table[name].column] = values * table[name].parameter.scale
    return batch.with_columns(**columns) if columns else batch


def propagate(
    spec: UncertaintySpec,
    registry: PluginRegistry,
    *,
    simulation: Simulation | None = None,
    confidence: float = 0.95,
    executor: Executor | None = None,
    archive: str | os.PathLike[str] | None = None,
    resume: bool = False,
) -> Propagation:
    """Sample ``spec``'s inputs and run one scene per sample (``simulation``: the spec's
    failure model with the registry's defaults otherwise; ``executor``: a process pool or
    a Dask client's executor, which the batch goes out to in chunks, with the same
    results bit for bit).

    With ``archive``, the samples run as a study of that archive (docs/archive.md): its
    scenes are the samples [SI], its one run the spec's model, its description the spec
    as read (distributions, seed, method); the study's name is a digest of the spec, so
    ``resume=True`` reads back a finished run of the same spec instead of running it."""
    if "speed_m_s" not in spec.at and "speed_m_s" not in spec.inputs:
        raise UncertaintySpecError(
            f"{spec.source}: speed_m_s: give it in at or in inputs (or ask for the limits)"
        )
    if simulation is None:
        simulation = Simulation.from_names(failure=spec.failure, registry=registry)
    inputs = sample_inputs(spec)
    batch = scenes(spec, inputs, registry)
    if archive is None:
        result = simulation.run_batch(batch, executor=executor)
    else:
        result = _archived(spec, batch, simulation, registry, archive, resume, executor)
    return Propagation(spec, inputs, result, confidence)


def spec_digest(spec: UncertaintySpec, **more: Any) -> str:
    """The SHA-256 of ``spec`` as described (and of ``more``, JSON values: what else
    a result depends on), not of where it was read from: the same spec, the same digest."""
    described = {**spec.describe(), "source": "", **more}
    return hashlib.sha256(json.dumps(described, sort_keys=True).encode()).hexdigest()


def study_name(spec: UncertaintySpec) -> str:
    """The archive's name for the study of ``spec``: the same spec, the same name."""
    return f"uncertainty-{spec_digest(spec)[:12]}"


def _archived(
    spec: UncertaintySpec,
    batch: SceneBatch,
    simulation: Simulation,
    registry: PluginRegistry,
    archive: str | os.PathLike[str],
    resume: bool,
    executor: Executor | None,
) -> BatchResult:
    from ..run.variant import Variant  # noqa: PLC0415
    from ..study.study import Study  # noqa: PLC0415

    described: dict[str, Any] = simulation.describe()
    slots = ("resistance", "failure", "integrator")
    variant = Variant(
        "model",
        **{slot: described[slot] for slot in slots},
        **{f"{slot}_settings": described[f"{slot}_settings"] for slot in slots},
        rest_speed_fraction=described["rest_speed_fraction"],
    )
    label = f"{spec.plate.material}/{spec.plate.thickness * 1e3:g}"
    study = Study(
        study_name(spec), batch, [variant], [label] * batch.size,
        description=json.dumps(spec.describe()),
    )  # fmt: skip
    found = study.run(
        archive=Path(os.fspath(archive)), resume=resume, executor=executor, registry=registry
    )
    return found["model"]
