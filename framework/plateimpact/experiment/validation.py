"""The model against measured shots: outcome agreement, residual-speed and exit-obliquity
errors, and how far each disagreeing shot lies from a boundary of the model.

Every shot is run as a scene (its own sphere where the shot file gives one). A shot with
an outcome is compared outcome to outcome; a go/no-go shot (only ``perforated`` known)
perforated or not. Speeds and angles are compared where the shot and the model both
leave the plate the same way (both perforate, or both ricochet and the shot records the
ricochet's exit speed). A disagreeing shot's distance is the distance along impact speed,
at its obliquity, to the nearest boundary of the model beyond which it gives what was
measured (the outcome, or perforation or not for a go/no-go shot): how far the shot's
speed is from one at which the model agrees, located by
:func:`plateimpact.limits.along_speed` (docs/experiment.md).
"""

from __future__ import annotations

import math
from collections.abc import Callable
from concurrent.futures import Executor
from typing import Any

import attrs
import numpy as np

from ..base.errors import ShotDataError, WorkBoundError
from ..limits import (
    SPEED_RESOLUTION,
    SPEED_TOLERANCE,
    LimitLine,
    Limits,
    Regime,
    along_speed,
)
from ..limits.chunked import run_chunked
from ..limits.plate_limits import check_steps
from ..model.bodies import MASS, RADIUS, Plate, Sphere
from ..model.results import Outcome
from ..model.scene import IMPACT_SPEED
from ..registry.plugin_registry import PluginRegistry
from ..run.simulation import Simulation
from ..storage.plate_file import plate_to_dict
from ..storage.shots import Shots

PERFORATED, NOT_PERFORATED = "perforated", "not perforated"
#: The rows of the confusion matrix: measured outcomes, then go/no-go shots.
MEASURED = (*(o.label for o in Outcome), PERFORATED, NOT_PERFORATED)
#: Its columns: the model's outcomes.
PREDICTED = tuple(o.label for o in Outcome)
#: The boundaries are sought this far beyond the slowest and fastest shot (factors).
SPAN_BELOW, SPAN_ABOVE = 0.5, 1.5
#: The most scenes validate runs unasked (as a sweep, the limits and the fits).
MAX_VALIDATE_SCENES = 1_000_000
_DEG = math.pi / 180.0


@attrs.frozen
class Disagreement:
    """A shot whose measured outcome the model does not give.

    ``impact_speed`` [m/s], ``impact_obliquity`` [rad]; ``measured`` a row name of the
    confusion matrix, ``predicted`` the model's outcome; ``boundary`` [m/s] the nearest
    boundary of the model across which what was compared changes, and ``distance`` [m/s]
    the shot's distance to it (None: none within the speeds searched).
    """

    label: str
    impact_speed: float
    impact_obliquity: float
    measured: str
    predicted: str
    boundary: float | None
    distance: float | None

    def to_json(self) -> dict[str, Any]:
        return {
            "label": self.label,
            "impact_speed_m_s": self.impact_speed,
            "impact_obliquity_deg": float(f"{self.impact_obliquity / _DEG:.12g}"),
            "measured": self.measured,
            "predicted": self.predicted,
            "boundary_m_s": self.boundary,
            "distance_to_boundary_m_s": self.distance,
        }


@attrs.frozen(eq=False)
class ValidationReport:
    """What :func:`validate` found; arrays have one entry per shot.

    Attributes
    ----------
    shots, sphere, plate, model
        The shots, the sphere of shots that give none, the plate and the simulation's
        plug-ins and settings.
    predicted_outcome, predicted_exit_speed, predicted_exit_obliquity : numpy.ndarray
        The model's :class:`~plateimpact.Outcome`, exit speed [m/s] and exit obliquity [rad].
    agrees : numpy.ndarray
        bool: the model gives the measured outcome (perforation, for go/no-go shots).
    agreement : float
        Weighted fraction of shots that agree, in [0, 1].
    confusion : dict
        measured (``MEASURED``) -> predicted (``PREDICTED``) -> number of shots.
    residual_speed_error, exit_obliquity_error : numpy.ndarray
        Model minus measured [m/s], [rad], NaN where the shot has no pair.
    residual_speed_rms, residual_speed_bias : float
        Weighted root mean square and mean of ``residual_speed_error`` over the pairs
        [m/s]; NaN when there is no pair.
    exit_obliquity_rms : float
        The same of ``exit_obliquity_error`` [rad].
    disagreements : tuple of Disagreement
        The shots that disagree, in file order.
    speeds : tuple of float
        The impact speeds over which boundaries were sought (start, stop) [m/s].
    limits : tuple of Limits
        The model's bands at the disagreeing shots' obliquities, one per sphere.
    """

    shots: Shots
    sphere: Sphere
    plate: Plate
    model: dict[str, Any]
    predicted_outcome: np.ndarray
    predicted_exit_speed: np.ndarray
    predicted_exit_obliquity: np.ndarray
    agrees: np.ndarray
    agreement: float
    confusion: dict[str, dict[str, int]]
    residual_speed_error: np.ndarray
    exit_obliquity_error: np.ndarray
    residual_speed_rms: float
    residual_speed_bias: float
    exit_obliquity_rms: float
    disagreements: tuple[Disagreement, ...]
    speeds: tuple[float, float]
    limits: tuple[Limits, ...]
    #: The simulation's plug-ins: the declarations of the plate's constants.
    registry: PluginRegistry = attrs.field(kw_only=True, repr=False)

    def to_json(self) -> dict[str, Any]:
        """One object in user units; null where no pair exists (never NaN)."""
        return {
            "shots": len(self.shots),
            "go_no_go_shots": int((self.shots.outcome == 0).sum()),
            "outcome_agreement": self.agreement,
            "agreeing_shots": int(self.agrees.sum()),
            "confusion": self.confusion,
            "residual_speed_rms_m_s": _or_null(self.residual_speed_rms),
            "residual_speed_bias_m_s": _or_null(self.residual_speed_bias),
            "residual_speed_pairs": int(np.isfinite(self.residual_speed_error).sum()),
            "exit_obliquity_rms_deg": _or_null(self.exit_obliquity_rms / _DEG),
            "exit_obliquity_pairs": int(np.isfinite(self.exit_obliquity_error).sum()),
            "disagreements": [d.to_json() for d in self.disagreements],
            "boundary_speeds_m_s": list(self.speeds),
            "plate": {
                k: v
                for k, v in plate_to_dict(self.plate, registry=self.registry).items()
                if k != "format"
            },
            "sphere": {
                RADIUS.key: self.sphere.radius / RADIUS.scale,
                MASS.key: self.sphere.mass / MASS.scale,
            },
            "model": self.model,
        }


def _or_null(x: float) -> float | None:
    return float(x) if math.isfinite(x) else None


def measured_classes(shots: Shots) -> list[str]:
    """The confusion-matrix row of each shot: its outcome, or whether it perforated."""
    return [
        Outcome(int(o)).label if o else (PERFORATED if p else NOT_PERFORATED)
        for o, p in zip(shots.outcome, shots.perforated, strict=True)
    ]


def _weighted(error: np.ndarray, weight: np.ndarray) -> tuple[float, float]:
    """(rms, mean) of the finite entries of ``error``, weighted; NaN if none weigh."""
    paired = np.isfinite(error)
    total = weight[paired].sum()
    if total <= 0.0:
        return math.nan, math.nan
    e, w = error[paired], weight[paired]
    return float(np.sqrt((w * e**2).sum() / total)), float((w * e).sum() / total)


def _exit_errors(
    shots: Shots, outcome: np.ndarray, speed: np.ndarray, obliquity: np.ndarray
) -> tuple[np.ndarray, np.ndarray]:
    """Model minus measured exit speed [m/s] and obliquity [rad] where both leave the
    plate the same way, NaN elsewhere."""
    ricochet = np.where(shots.outcome == Outcome.RICOCHET, Outcome.RICOCHET, 0)
    kind = np.where(shots.perforated, Outcome.PERFORATION, ricochet)
    same = (kind != 0) & (kind == outcome)
    # A residual speed of 0 says "did not perforate", not a measured speed.
    with_speed = same & (shots.residual_speed > 0.0)
    speed_error = np.where(with_speed, speed - shots.residual_speed, math.nan)
    with_angle = same & np.isfinite(shots.exit_obliquity)
    return speed_error, np.where(with_angle, obliquity - shots.exit_obliquity, math.nan)


def boundary_speeds(shots: Shots) -> tuple[float, float]:
    """The impact speeds [m/s] over which boundaries are sought: from half the slowest
    shot to 1.5 times the fastest, within the model's range of speeds."""
    low = max(SPAN_BELOW * float(shots.impact_speed.min()), IMPACT_SPEED.range.low)
    high = min(SPAN_ABOVE * float(shots.impact_speed.max()), IMPACT_SPEED.range.high)
    return low, high


def work_estimate(
    shots: Shots, sphere: Sphere, speeds: tuple[float, float], resolution: float
) -> tuple[int, int, int]:
    """(scenes at most, lines, samples a line): every shot's scene, and the boundary
    search's scan along every line (distinct sphere and obliquity) as if a shot on each
    disagreed; which do is known only once the shots have run."""
    radius, mass = shots.spheres(sphere)
    lines = len(np.unique(np.column_stack([radius, mass, shots.impact_obliquity]), axis=0))
    per_line = math.ceil((speeds[1] - speeds[0]) / resolution) + 1
    return len(shots) + lines * per_line, lines, per_line


def check_work(
    shots: Shots,
    sphere: Sphere,
    speeds: tuple[float, float],
    resolution: float,
    max_scenes: int | None,
) -> None:
    """:class:`WorkBoundError` if ``work_estimate`` passes ``max_scenes``."""
    scenes, lines, per_line = work_estimate(shots, sphere, speeds, resolution)
    if max_scenes is not None and scenes > max_scenes:
        raise WorkBoundError(
            "max_scenes",
            f"validate: up to {scenes:,} scenes ({len(shots):,} shots, and the boundaries "
            f"along {lines:,} lines (sphere and obliquity) of {per_line:,} samples should "
            f"a shot on each disagree), more than {max_scenes:,}: validate fewer shots or "
            "obliquities at once, or lift the bound (max_scenes=None; --force)",
        )


def _nearest(line: LimitLine, speed: float, measured: Callable[[Regime], bool]) -> float | None:
    """The boundary of ``line`` nearest ``speed`` [m/s] beyond which the model gives what
    was measured (``measured(regime)``: the outcome, or for a go/no-go shot whether it
    perforated): the near edge of the nearest band that agrees. None if no band of the
    line agrees (the line's own ends are not boundaries)."""
    edges = [
        edge
        for k, band in enumerate(line.bands)
        if measured(band.regime)
        for edge, inner in ((band.start, k > 0), (band.end, k < len(line.bands) - 1))
        if inner
    ]
    return min(edges, key=lambda at: abs(at - speed)) if edges else None


def _measured_regime(outcome: int, perforated: bool) -> Callable[[Regime], bool]:
    """Whether a model regime gives what a shot measured."""
    if outcome:
        return lambda regime: regime.outcome is Outcome(outcome)
    return lambda regime: (regime.outcome is Outcome.PERFORATION) == perforated


def _disagreements(
    simulation: Simulation,
    shots: Shots,
    sphere: Sphere,
    plate: Plate,
    predicted: np.ndarray,
    agrees: np.ndarray,
    speeds: tuple[float, float],
    tolerance: float,
    resolution: float,
    executor: Executor | None,
) -> tuple[tuple[Disagreement, ...], tuple[Limits, ...]]:
    """The disagreeing shots with their nearest boundaries: one limits search per sphere,
    over all the obliquities of that sphere's disagreeing shots."""
    radius, mass = shots.spheres(sphere)
    wrong = np.flatnonzero(~agrees)
    boundary: dict[int, float | None] = {}
    found = []
    for r, m in dict.fromkeys(zip(radius[wrong], mass[wrong], strict=True)):
        mine = wrong[(radius[wrong] == r) & (mass[wrong] == m)]
        obliquities = np.unique(shots.impact_obliquity[mine])
        limits = along_speed(
            simulation, Sphere(radius=float(r), mass=float(m)), plate, obliquities, speeds,
            tolerance=tolerance, resolution=resolution, executor=executor,
            max_scenes=None,  # validate bounded the whole search before any scene ran
        )  # fmt: skip
        found.append(limits)
        for i in mine:
            line = limits.lines[int(np.searchsorted(obliquities, shots.impact_obliquity[i]))]
            wanted = _measured_regime(int(shots.outcome[i]), bool(shots.perforated[i]))
            boundary[int(i)] = _nearest(line, shots.impact_speed[i], wanted)
    classes = measured_classes(shots)
    disagreements = tuple(
        Disagreement(
            shots.labels[int(i)],
            float(shots.impact_speed[i]),
            float(shots.impact_obliquity[i]),
            classes[i],
            Outcome(int(predicted[i])).label,
            boundary[int(i)],
            _distance(shots.impact_speed[i], boundary[int(i)]),
        )
        for i in wrong
    )
    return disagreements, tuple(found)


def _distance(speed: float, boundary: float | None) -> float | None:
    return None if boundary is None else float(abs(speed - boundary))


def validate(
    simulation: Simulation,
    sphere: Sphere,
    plate: Plate,
    shots: Shots,
    *,
    tolerance: float = SPEED_TOLERANCE,
    resolution: float = SPEED_RESOLUTION,
    executor: Executor | None = None,
    max_scenes: int | None = MAX_VALIDATE_SCENES,
) -> ValidationReport:
    """Run the model on every shot and score it (see the module's description).

    ``sphere`` is the sphere of shots whose file gives no radius or mass; ``tolerance``
    and ``resolution`` [m/s] are those of the boundary search
    (:func:`plateimpact.limits.along_speed`). Before any scene runs: :class:`ShotDataError`
    when every shot has weight 0 (nothing to score), :class:`ParameterError` for a
    tolerance or resolution out of range, and
    :class:`~plateimpact.base.errors.WorkBoundError` when the shots' scenes and the boundary
    search could together pass ``max_scenes`` (None: no bound; ``work_estimate``).
    The shots run RUN_CHUNK at a time.
    """
    if not shots.weight.sum() > 0.0:
        raise ShotDataError(f"{shots.source}: every shot has weight 0: nothing to score")
    speeds = boundary_speeds(shots)
    check_steps(tolerance, resolution, speeds, 1, "m/s", 1.0, None)
    check_work(shots, sphere, speeds, resolution, max_scenes)
    scenes = shots.scenes(sphere, plate)
    outputs = {name: np.empty(len(shots)) for name in ("outcome", "exit_speed", "exit_obliquity")}
    for where, part in run_chunked(simulation, scenes.take, len(shots), executor):
        for name, values in outputs.items():
            values[where] = getattr(part, name)
    predicted = outputs["outcome"].astype(int)
    agrees = np.where(
        shots.outcome != 0,
        shots.outcome == predicted,
        shots.perforated == (predicted == Outcome.PERFORATION),
    )
    classes = measured_classes(shots)
    confusion = {row: dict.fromkeys(PREDICTED, 0) for row in MEASURED}
    for row, column in zip(classes, predicted, strict=True):
        confusion[row][Outcome(int(column)).label] += 1
    speed_error, angle_error = _exit_errors(
        shots, predicted, outputs["exit_speed"], outputs["exit_obliquity"]
    )
    speed_rms, speed_bias = _weighted(speed_error, shots.weight)
    disagreements, limits = _disagreements(
        simulation, shots, sphere, plate, predicted, agrees, speeds, tolerance, resolution,
        executor,
    )  # fmt: skip
    return ValidationReport(
        shots=shots,
        sphere=sphere,
        plate=plate,
        model=simulation.describe(),
        predicted_outcome=predicted,
        predicted_exit_speed=np.asarray(outputs["exit_speed"], dtype=float),
        predicted_exit_obliquity=np.asarray(outputs["exit_obliquity"], dtype=float),
        agrees=agrees,
        agreement=float((shots.weight * agrees).sum() / shots.weight.sum()),
        confusion=confusion,
        residual_speed_error=speed_error,
        exit_obliquity_error=angle_error,
        residual_speed_rms=speed_rms,
        residual_speed_bias=speed_bias,
        exit_obliquity_rms=_weighted(angle_error, shots.weight)[0],
        disagreements=disagreements,
        speeds=speeds,
        limits=limits,
        registry=simulation.registry,
    )
