"""What an impact ends in: outcome, exit state, failure, and optionally the trajectory."""

from __future__ import annotations

import enum
import math
from typing import TYPE_CHECKING

import attrs
import numpy as np

if TYPE_CHECKING:
    from .crater import CraterSections


class Outcome(enum.IntEnum):
    """How an impact ends (0 is reserved for "not finished" inside integrators)."""

    RICOCHET = 1
    EMBEDMENT = 2
    PERFORATION = 3

    @property
    def label(self) -> str:
        """Lower-case name, as the CLI and archives write it."""
        return self.name.lower()


#: Columns of a recorded trajectory, with units.
TRAJECTORY_FIELDS = {
    "time": "s",
    "penetration": "m",
    "lateral": "m",
    "obliquity": "rad",
    "speed": "m/s",
}


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
        """The result in the user's units (mm, m/s, s, degrees), as the CLI prints it."""
        return {
            "outcome": self.outcome.label,
            "exit_speed_m_s": self.exit_speed,
            "exit_obliquity_deg": self.exit_obliquity_deg,
            "contact_time_s": self.contact_time,
            "max_penetration_mm": self.max_penetration * 1e3,
            "plate_failed": self.plate_failed,
            "failure_time_s": None if not self.plate_failed else self.failure_time,
            "failure_penetration_mm": None
            if not self.plate_failed
            else self.failure_penetration * 1e3,
            "failure_lateral_mm": None if not self.plate_failed else self.failure_lateral * 1e3,
        }


#: Per-scene result columns of a batch, with units.
RESULT_FIELDS = {
    "outcome": "",
    "exit_speed": "m/s",
    "exit_obliquity": "rad",
    "contact_time": "s",
    "max_penetration": "m",
    "plate_failed": "",
    "failure_time": "s",
    "failure_penetration": "m",
    "failure_lateral": "m",
}


class BatchResult:
    """Results of a batch as arrays (one entry per scene, in the batch's order).

    Trajectories, when recorded, are stored as contiguous ragged arrays: every sample of
    every scene concatenated in ``trajectory[field]``, scene ``i`` owning the slice
    ``trajectory_offsets[i]:trajectory_offsets[i + 1]``. Crater sections, when asked for,
    are a :class:`~plateimpact.crater.CraterSections` in ``craters``.
    """

    def __init__(
        self,
        columns: dict[str, np.ndarray],
        trajectory: dict[str, np.ndarray] | None = None,
        trajectory_counts: np.ndarray | None = None,
        stats: dict[str, float] | None = None,
        craters: CraterSections | None = None,
    ) -> None:
        missing = set(RESULT_FIELDS) - set(columns)
        if missing:
            raise ValueError(f"result columns missing: {sorted(missing)}")
        self.columns = columns
        self.trajectory = trajectory
        self.trajectory_counts = trajectory_counts
        self.stats = stats or {}
        self.craters = craters
        if trajectory_counts is not None:
            self.trajectory_offsets = np.concatenate([[0], np.cumsum(trajectory_counts)])

    @classmethod
    def concat(cls, parts: list[BatchResult]) -> BatchResult:
        """One result holding ``parts`` in order (e.g. the chunks of a threaded run)."""
        columns = {k: np.concatenate([p.columns[k] for p in parts]) for k in parts[0].columns}
        stats = {k: sum(p.stats.get(k, 0) for p in parts) for k in parts[0].stats}
        craters = None
        if parts[0].craters is not None:
            craters = type(parts[0].craters).concat([p.craters for p in parts])
        if parts[0].trajectory is None:
            return cls(columns, stats=stats, craters=craters)
        trajectory = {
            k: np.concatenate([p.trajectory[k] for p in parts]) for k in parts[0].trajectory
        }
        counts = np.concatenate([p.trajectory_counts for p in parts])
        return cls(columns, trajectory, counts, stats, craters)

    def __len__(self) -> int:
        return self.columns["outcome"].size

    def take(self, index: np.ndarray) -> BatchResult:
        """The results of the scenes ``index`` (integer array), trajectories included."""
        index = np.asarray(index, dtype=int)
        columns = {k: c[index] for k, c in self.columns.items()}
        craters = None if self.craters is None else self.craters.take(index)
        if self.trajectory is None:
            return BatchResult(columns, stats=dict(self.stats), craters=craters)
        pieces = [
            np.arange(self.trajectory_offsets[i], self.trajectory_offsets[i + 1]) for i in index
        ]
        samples = np.concatenate(pieces) if pieces else np.zeros(0, dtype=int)
        trajectory = {k: x[samples] for k, x in self.trajectory.items()}
        counts = self.trajectory_counts[index]
        return BatchResult(columns, trajectory, counts, dict(self.stats), craters)

    def __getattr__(self, name: str) -> np.ndarray:
        try:
            return self.__dict__["columns"][name]
        except KeyError:
            raise AttributeError(f"BatchResult has no column {name!r}") from None

    def trajectory_of(self, i: int) -> Trajectory | None:
        """The trajectory of scene ``i``, or None when none was recorded."""
        if self.trajectory is None:
            return None
        lo, hi = self.trajectory_offsets[i], self.trajectory_offsets[i + 1]
        state = {
            k.removeprefix("failure_"): v[lo:hi]
            for k, v in self.trajectory.items()
            if k.startswith("failure_")
        }
        return Trajectory(
            **{k: self.trajectory[k][lo:hi] for k in TRAJECTORY_FIELDS}, failure_state=state
        )

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
