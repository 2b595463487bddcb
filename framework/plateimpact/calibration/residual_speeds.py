"""The model's residual speeds at normal incidence for candidate plate constants, the
shots a DRI fit takes, and the declared ranges a fit must stay in: for fitting any
declared plate constants of any model (docs/calibration.md)."""

from __future__ import annotations

from collections.abc import Mapping, Sequence

import numpy as np

from ..base.errors import CalibrationError, ShotDataError
from ..base.parameters import Range
from ..limits.chunked import run_chunked
from ..model.batch import SceneBatch
from ..model.bodies import Plate, Sphere
from ..model.results import Outcome
from ..run.simulation import Simulation
from ..storage.shots import Shots
from .dri import MIN_PERFORATIONS, DriFit, fit_dri


def model_residual_speeds(
    simulation: Simulation,
    sphere: Sphere,
    plate: Plate,
    impact_speeds: np.ndarray,
    constants: Sequence[Mapping[str, float]],
) -> np.ndarray:
    """Residual speeds [m/s] of the model at normal incidence, shape (len(constants),
    len(impact_speeds)), at ``impact_speeds`` [m/s], for each mapping of plate constants
    [SI] in ``constants`` (each names the same constants; they replace the plate's). One
    batch, run RUN_CHUNK scenes at a time. Embedments give 0."""
    speeds = np.asarray(impact_speeds, dtype=float)
    names = list(constants[0])
    candidate = {n: np.array([c[n] for c in constants], dtype=float) for n in names}
    fixed = {name: value for name, value in plate.constants if name not in candidate}

    def batch_of(index: np.ndarray) -> SceneBatch:
        k, i = np.divmod(index, speeds.size)  # constants-major, as the rows
        return SceneBatch(
            {
                "radius": np.full(index.size, sphere.radius),
                "mass": np.full(index.size, sphere.mass),
                "thickness": np.full(index.size, plate.thickness),
                "impact_speed": speeds[i],
                "impact_obliquity": np.zeros(index.size),
                **{name: values[k] for name, values in candidate.items()},
                **{name: np.full(index.size, value) for name, value in fixed.items()},
            }
        )

    residual = np.empty(len(constants) * speeds.size)
    for where, result in run_chunked(simulation, batch_of, residual.size):
        residual[where] = np.where(result.outcome == Outcome.PERFORATION, result.exit_speed, 0.0)
    return residual.reshape(len(constants), speeds.size)


def normal_shots(shots: Shots, fitted: str) -> Shots:
    """The shots at normal incidence that record a residual speed, with at least three
    perforations (ShotDataError); ``fitted`` names what the fit finds, for messages
    (``"a and b"``)."""
    normal = shots.normal_incidence()
    # A DRI fit reads a residual speed > 0 as a perforation: go/no-go shots (no residual
    # speed) and a rebound's exit speed tell it nothing.
    residual = normal.residual_speed
    normal = normal.take(np.isfinite(residual) & ((residual > 0.0) == normal.perforated))
    # The fits run one sphere and weigh every shot alike: refuse, not ignore.
    own = np.isfinite(normal.radius) | np.isfinite(normal.mass) | (normal.weight != 1.0)
    if own.any():
        raise ShotDataError(
            f"{normal.labels[int(np.argmax(own))]}: the fits of {fitted} take one sphere "
            "(--radius, --mass) and equal weights: remove radius_mm, mass_g and weight "
            "from the normal-incidence shots"
        )
    perforating = [label for label, p in zip(normal.labels, normal.perforated, strict=True) if p]
    if len(perforating) < MIN_PERFORATIONS:
        listed = f" ({', '.join(perforating)})" if perforating else ""
        raise ShotDataError(
            f"{shots.source}: {len(perforating)} perforating shots at normal incidence{listed}; "
            f"the DRI fit needs at least {MIN_PERFORATIONS}"
        )
    return normal


def fit_model_dri(speeds: np.ndarray, residual: np.ndarray) -> DriFit | None:
    """The DRI fit of model output, ``speeds`` [m/s] and ``residual`` [m/s], or None where
    it is unusable (too few perforations)."""
    try:
        return fit_dri(speeds, residual)
    except CalibrationError:
        return None


def declared_ranges(simulation: Simulation, names: Sequence[str]) -> list[tuple[str, Range | None]]:
    """The range the model declares for each plate constant of ``names`` (None: none)."""
    declared = simulation.model.plate_constants()
    return [(name, declared[name].range if name in declared else None) for name in names]


def in_model_domain(simulation: Simulation, values: Mapping[str, float]) -> bool:
    """Whether plate constants ``values`` [SI] are > 0 (fits in logarithms need it) and
    lie in the ranges the model declares for them, where a trial of a fit may be run."""
    ranges = declared_ranges(simulation, list(values))
    return all(
        value > 0.0 and (allowed is None or bool(allowed.contains(value)))
        for value, (_, allowed) in zip(values.values(), ranges, strict=True)
    )


def log_domain(simulation: Simulation, names: Sequence[str]) -> tuple[np.ndarray, np.ndarray]:
    """The model's ranges of the plate constants ``names`` as bounds on their logarithms."""
    low, high = np.full(len(names), -np.inf), np.full(len(names), np.inf)
    for k, (_, allowed) in enumerate(declared_ranges(simulation, names)):
        if allowed is not None:
            with np.errstate(divide="ignore"):  # ln 0 = -inf: no lower bound
                low[k], high[k] = np.log(allowed.low), np.log(allowed.high)
    return low, high
