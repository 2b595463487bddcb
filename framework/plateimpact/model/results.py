"""What an impact ends in: outcome, exit state, failure, and optionally the trajectory."""

from __future__ import annotations

import enum
import math

import attrs
import numpy as np

from ..base.parameters import Parameter
from ..base.units import deg, mm
from .ragged import Ragged


class Outcome(enum.IntEnum):
    """How an impact ends (0 is reserved for "not finished" inside integrators)."""

    RICOCHET = 1
    EMBEDMENT = 2
    PERFORATION = 3

    @property
    def label(self) -> str:
        """Lower-case name, as the CLI and archives write it."""
        return self.name.lower()


#: Per-scene result columns, with their units: the one source of what archives, CSV
#: headers and JSON keys call them.
RESULT_FIELDS: dict[str, Parameter] = {
    p.name: p
    for p in (
        Parameter("outcome", "1 ricochet, 2 embedment, 3 perforation", kind=int),
        Parameter("exit_speed", "speed when contact ends (0 for embedment)", "m/s"),
        Parameter(
            "exit_obliquity",
            "direction from the plate normal when contact ends, or at rest",
            "rad",
            display_unit="deg",
            scale=deg,
        ),
        Parameter("contact_time", "time from first contact to the outcome", "s"),
        Parameter(
            "max_penetration", "largest penetration P reached", "m", display_unit="mm", scale=mm
        ),
        Parameter(
            "plate_failed", "whether the plate failed (P reached the onset penetration)", kind=bool
        ),
        Parameter("failure_time", "time of plate failure (NaN: none)", "s"),
        Parameter(
            "failure_penetration",
            "penetration at plate failure (NaN: none)",
            "m",
            display_unit="mm",
            scale=mm,
        ),
        Parameter(
            "failure_lateral",
            "lateral displacement at plate failure (NaN: none)",
            "m",
            display_unit="mm",
            scale=mm,
        ),
    )
}
#: Columns of a recorded trajectory (then ``failure_<state>`` for the failure state).
TRAJECTORY_FIELDS: dict[str, Parameter] = {
    p.name: p
    for p in (
        Parameter("time", "time since first contact", "s"),
        Parameter(
            "penetration",
            "depth P of the sphere's deepest point below the front surface",
            "m",
            display_unit="mm",
            scale=mm,
        ),
        Parameter(
            "lateral",
            "lateral displacement Y of the sphere's centre",
            "m",
            display_unit="mm",
            scale=mm,
        ),
        Parameter(
            "obliquity",
            "direction theta of the velocity from the plate normal",
            "rad",
            display_unit="deg",
            scale=deg,
        ),
        Parameter("speed", "speed V", "m/s"),
    )
}
#: Columns of crater sections (eqs 31-39): per point, then per scene.
CRATER_FIELDS: dict[str, Parameter] = {
    p.name: p
    for p in (
        Parameter(
            "lateral",
            "distance along the plate from the crater's entry point",
            "m",
            display_unit="mm",
            scale=mm,
        ),
        Parameter(
            "depth",
            "depth of the crater floor below the front surface",
            "m",
            display_unit="mm",
            scale=mm,
        ),
        Parameter(
            "impact_point",
            "lateral position of first contact in the section's coordinates",
            "m",
            display_unit="mm",
            scale=mm,
        ),
    )
}


@attrs.frozen(eq=False)
class CraterSection:
    """The crater floor in the plane of motion, from entry to exit.

    Attributes
    ----------
    lateral : ndarray
        Distance along the plate from the crater's entry point [m]; starts at 0.
    depth : ndarray
        Depth of the floor below the front surface [m], >= 0; starts at 0.
    impact_point : float
        Lateral position of the first-contact point in these coordinates [m].
    """

    lateral: np.ndarray
    depth: np.ndarray
    impact_point: float

    @property
    def length(self) -> float:
        """Crater length along the plate [m]."""
        return float(self.lateral[-1] - self.lateral[0])

    @property
    def max_depth(self) -> float:
        """Deepest point of the floor [m]."""
        return float(self.depth.max())


@attrs.frozen(eq=False)
class Trajectory:
    """The sampled path of the sphere's centre, one entry per integrator step.

    Attributes: time [s]; penetration P [m] (depth of the sphere's deepest point);
    lateral Y [m]; obliquity θ [rad]; speed V [m/s]; failure_state, the failure model's
    state variables by name (e.g. ``finger_angle`` [rad]), meaningful from failure on.
    """

    time: np.ndarray
    penetration: np.ndarray
    lateral: np.ndarray
    obliquity: np.ndarray
    speed: np.ndarray
    failure_state: dict[str, np.ndarray] = attrs.field(factory=dict)


@attrs.frozen
class Result:
    """The outcome of one scene.

    Attributes
    ----------
    outcome : Outcome
    exit_speed : float
        Speed when contact ends [m/s]; 0 for an embedment.
    exit_obliquity : float
        Direction when contact ends [rad]: in (π/2, π] for a ricochet, [0, π/2) for a
        perforation; for an embedment, the direction at rest (docs/model.md, "rest").
    contact_time : float
        Time from first contact to the outcome [s].
    max_penetration : float
        Largest P reached [m].
    plate_failed : bool
        Whether P reached the critical penetration.
    failure_time, failure_penetration, failure_lateral : float
        When [s] and where (P [m], Y [m]) the plate failed; NaN if it did not.
    trajectory : Trajectory or None
        Present when it was asked for.
    """

    outcome: Outcome
    exit_speed: float
    exit_obliquity: float
    contact_time: float
    max_penetration: float
    plate_failed: bool
    failure_time: float = math.nan
    failure_penetration: float = math.nan
    failure_lateral: float = math.nan
    trajectory: Trajectory | None = attrs.field(default=None, eq=False, repr=False)

    @property
    def exit_obliquity_deg(self) -> float:
        """Exit obliquity [deg]."""
        return math.degrees(self.exit_obliquity)

    def as_user_dict(self) -> dict[str, object]:
        """The result in the user's units (mm, m/s, s, degrees), keys with their units
        (``exit_speed_m_s``), as the CLI prints it; failure values None if it did not."""
        out: dict[str, object] = {"outcome": self.outcome.label}
        for name, field in RESULT_FIELDS.items():
            value = getattr(self, name)
            if name == "outcome":
                continue
            if name.startswith("failure_") and not self.plate_failed:
                out[field.key] = None
            elif isinstance(value, float):
                out[field.key] = value / field.scale
            else:
                out[field.key] = value
        return out


class BatchResult:
    """Results of a batch as arrays (one entry per scene, in the batch's order).

    ``trajectory`` (when recorded) and ``craters`` (when asked for) are
    :class:`~plateimpact.model.ragged.Ragged` arrays with one row per scene: the trajectory's
    columns are :data:`TRAJECTORY_FIELDS` then ``failure_<state>``; the craters' are
    ``lateral`` and ``depth`` per point and ``impact_point`` per scene
    (:data:`CRATER_FIELDS`). ``stats`` counts the integrator's work.
    """

    def __init__(
        self,
        columns: dict[str, np.ndarray],
        trajectory: Ragged | None = None,
        stats: dict[str, int] | None = None,
        craters: Ragged | None = None,
    ) -> None:
        missing = set(RESULT_FIELDS) - set(columns)
        if missing:
            raise ValueError(f"result columns missing: {sorted(missing)}")
        self.columns = columns
        self.trajectory = trajectory
        self.stats = stats or {}
        self.craters = craters

    @classmethod
    def concat(cls, parts: list[BatchResult]) -> BatchResult:
        """One result holding ``parts`` in order (e.g. the chunks of a parallel run)."""
        columns = {k: np.concatenate([p.columns[k] for p in parts]) for k in parts[0].columns}
        stats = {k: sum(p.stats.get(k, 0) for p in parts) for k in parts[0].stats}
        trajectory = craters = None
        if parts[0].trajectory is not None:
            trajectory = Ragged.concat([p.trajectory for p in parts])  # type: ignore[misc]
        if parts[0].craters is not None:
            craters = Ragged.concat([p.craters for p in parts])  # type: ignore[misc]
        return cls(columns, trajectory, stats, craters)

    def __len__(self) -> int:
        return int(self.columns["outcome"].size)

    def take(self, index: np.ndarray) -> BatchResult:
        """The results of the scenes ``index`` (integer array), trajectories included."""
        index = np.asarray(index, dtype=int)
        return BatchResult(
            {k: c[index] for k, c in self.columns.items()},
            None if self.trajectory is None else self.trajectory.take(index),
            dict(self.stats),
            None if self.craters is None else self.craters.take(index),
        )

    def __getattr__(self, name: str) -> np.ndarray:
        try:
            return self.__dict__["columns"][name]
        except KeyError:
            raise AttributeError(f"BatchResult has no column {name!r}") from None

    def trajectory_of(self, i: int) -> Trajectory | None:
        """The trajectory of scene ``i``, or None when none was recorded."""
        if self.trajectory is None:
            return None
        row = self.trajectory.row(i)
        state = {k.removeprefix("failure_"): v for k, v in row.items() if k.startswith("failure_")}
        return Trajectory(**{k: row[k] for k in TRAJECTORY_FIELDS}, failure_state=state)

    def crater_of(self, i: int) -> CraterSection | None:
        """The crater section of scene ``i``, or None when none was computed."""
        if self.craters is None:
            return None
        row = self.craters.row(i)
        return CraterSection(row["lateral"], row["depth"], float(self.craters["impact_point"][i]))

    def result(self, i: int) -> Result:
        """Scene ``i`` as a :class:`Result`."""
        c = self.columns
        return Result(
            outcome=Outcome(int(c["outcome"][i])),
            exit_speed=float(c["exit_speed"][i]),
            exit_obliquity=float(c["exit_obliquity"][i]),
            contact_time=float(c["contact_time"][i]),
            max_penetration=float(c["max_penetration"][i]),
            plate_failed=bool(c["plate_failed"][i]),
            failure_time=float(c["failure_time"][i]),
            failure_penetration=float(c["failure_penetration"][i]),
            failure_lateral=float(c["failure_lateral"][i]),
            trajectory=self.trajectory_of(i),
        )

    def results(self) -> list[Result]:
        """Every scene as a :class:`Result`."""
        return [self.result(i) for i in range(len(self))]
