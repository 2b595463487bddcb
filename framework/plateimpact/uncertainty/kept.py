"""An uncertainty study's results computed once and kept: the sampled limits, the Sobol'
indices and the probability maps, each stored in an archive as it is computed and read
back on ``resume`` instead of computed again (uncertainty.archived; the propagation's own
samples are a study of the same archive: uncertainty.propagation).

>>> found = kept_limits(spec, registry, [0, 45], "runs.h5")          # computed, stored
>>> again = kept_limits(spec, registry, [0, 45], "runs.h5", resume=True)  # read back
"""

from __future__ import annotations

import os
from collections.abc import Sequence
from concurrent.futures import Executor
from typing import Any

import attrs
import numpy as np

from ..registry.plugin_registry import PluginRegistry
from ..run.simulation import Simulation
from ..storage.archive import Archive
from ..storage.records import LIMITS
from .archived import (
    KIND_INDICES,
    KIND_LIMITS,
    KIND_MAP,
    code_record,
    indices_from_record,
    indices_to_record,
    kept_or_computed,
    limits_from_record,
    limits_to_record,
    map_from_record,
    map_to_record,
    record_name,
)
from .curves import OutcomeGrid, outcome_grid
from .limit_search import RESOLUTION, SPEEDS, TOLERANCE
from .limits import SampledLimits, sampled_limits_at
from .sensitivity import SobolIndices, ballistic_limit_indices, perforation_indices
from .spec import UncertaintySpec

#: The quantities whose Sobol' indices can be asked for.
QUANTITIES = ("perforation", "ballistic_limit")
#: The settings of every sampled-limit search (recorded, and part of a record's name).
SEARCH = {"speeds_m_s": list(SPEEDS), "tolerance_m_s": TOLERANCE, "resolution_m_s": RESOLUTION}


@attrs.frozen
class Kept:
    """Where a result is kept: the archive (None: nowhere) and the record's name."""

    archive: Archive | None
    name: str

    @property
    def record(self) -> str | None:
        """``limits/NAME`` as ``show`` and ``compare`` name it (None: not kept)."""
        return None if self.archive is None else f"{LIMITS}/{self.name}"


def _archive(archive: Archive | str | os.PathLike[str] | None) -> Archive | None:
    return archive if archive is None or isinstance(archive, Archive) else Archive(archive)


def _simulation(
    spec: UncertaintySpec, registry: PluginRegistry, given: Simulation | None
) -> Simulation:
    return given or Simulation.from_names(failure=spec.failure, registry=registry)


def kept_limits(
    spec: UncertaintySpec,
    registry: PluginRegistry,
    obliquities_deg: Sequence[float] | np.ndarray,
    archive: Archive | str | os.PathLike[str] | None = None,
    *,
    resume: bool = False,
    simulation: Simulation | None = None,
    executor: Executor | None = None,
) -> tuple[tuple[SampledLimits, ...], Kept]:
    """:func:`~.limits.sampled_limits_at`, kept in ``archive``."""
    simulation = _simulation(spec, registry, simulation)
    angles = np.atleast_1d(np.asarray(obliquities_deg, dtype=float))
    settings = {"obliquities_deg": angles.tolist(), **SEARCH}
    kept = Kept(_archive(archive), record_name(spec, KIND_LIMITS, settings))
    found = kept_or_computed(
        kept.archive, kept.name, resume=resume, code=code_record(simulation, True), spec=spec,
        compute=lambda: sampled_limits_at(spec, registry, angles, simulation=simulation,
                                          executor=executor),
        to_record=lambda f: limits_to_record(f, simulation, settings),
        from_record=lambda r, w: limits_from_record(r, spec, registry, w),
    )  # fmt: skip
    return found, kept


def kept_indices(
    spec: UncertaintySpec,
    registry: PluginRegistry,
    base_samples: int,
    quantities: Sequence[str] = ("perforation",),
    archive: Archive | str | os.PathLike[str] | None = None,
    *,
    resume: bool = False,
    simulation: Simulation | None = None,
    executor: Executor | None = None,
) -> tuple[dict[str, SobolIndices], Kept]:
    """The Sobol' indices of each of ``quantities`` (:data:`QUANTITIES`; uncertainty.
    sensitivity), by quantity, kept in ``archive``."""
    simulation = _simulation(spec, registry, simulation)
    searched = "ballistic_limit" in quantities
    settings: dict[str, Any] = {"base_samples": base_samples, "quantities": list(quantities)}
    if searched:
        settings.update(SEARCH)
    kept = Kept(_archive(archive), record_name(spec, KIND_INDICES, settings))
    find = {"perforation": perforation_indices, "ballistic_limit": ballistic_limit_indices}

    def compute() -> dict[str, SobolIndices]:
        return {
            q: find[q](spec, registry, base_samples, simulation=simulation, executor=executor)
            for q in quantities
        }

    found = kept_or_computed(
        kept.archive, kept.name, resume=resume, code=code_record(simulation, searched),
        spec=spec, compute=compute,
        to_record=lambda f: indices_to_record(f, spec, simulation, settings),
        from_record=indices_from_record,
    )  # fmt: skip
    return found, kept


def kept_map(
    spec: UncertaintySpec,
    registry: PluginRegistry,
    speeds_m_s: np.ndarray | None,
    obliquities_deg: np.ndarray | None,
    archive: Archive | str | os.PathLike[str] | None = None,
    *,
    resume: bool = False,
    simulation: Simulation | None = None,
    executor: Executor | None = None,
) -> tuple[OutcomeGrid, Kept]:
    """:func:`~.curves.outcome_grid` (a curve or a map), kept in ``archive``."""
    simulation = _simulation(spec, registry, simulation)
    settings = {
        "speeds_m_s": None if speeds_m_s is None else np.asarray(speeds_m_s, float).tolist(),
        "obliquities_deg": None
        if obliquities_deg is None
        else np.asarray(obliquities_deg, float).tolist(),
    }
    kept = Kept(_archive(archive), record_name(spec, KIND_MAP, settings))
    found = kept_or_computed(
        kept.archive, kept.name, resume=resume, code=code_record(simulation, False), spec=spec,
        compute=lambda: outcome_grid(spec, registry, speeds_m_s, obliquities_deg,
                                     simulation=simulation, executor=executor),
        to_record=lambda f: map_to_record(f, simulation, settings),
        from_record=lambda r, w: map_from_record(r, spec, w),
    )  # fmt: skip
    return found, kept
