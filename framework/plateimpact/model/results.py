"""What an impact ends in: outcome, exit state, failure, and optionally the trajectory.

Each object shows in a notebook as a short text and a small table in user units
(:mod:`.views`); a batch's results, with the scenes they are of, as an xarray Dataset or
a pandas DataFrame (:mod:`.tables`).
"""

from __future__ import annotations

import math
from typing import TYPE_CHECKING

import attrs
import numpy as np

from . import views
from .batch import SceneBatch
from .fields import CRATER_FIELDS, RESULT_FIELDS, TRAJECTORY_FIELDS, Outcome
from .ragged import Ragged
from .tables import LabelledTable, SceneInputs, scene_table

if TYPE_CHECKING:
    import pandas
    import xarray

__all__ = [
    "CRATER_FIELDS",
    "RESULT_FIELDS",
    "TRAJECTORY_FIELDS",
    "BatchResult",
    "CraterSection",
    "Outcome",
    "Result",
    "Trajectory",
]


@attrs.frozen(eq=False, repr=False)
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

    def __repr__(self) -> str:
        return views.crater_repr(np.asarray(self.lateral), np.asarray(self.depth))


@attrs.frozen(eq=False, repr=False)
class Trajectory:
    """The sampled path of the sphere's centre, one entry per integrator step.

    Attributes: time [s]; penetration P [m] (depth of the sphere's deepest point);
    lateral Y [m]; obliquity θ [rad]; speed V [m/s]; failure_state, the failure model's
    state variables by name (e.g. ``finger_angle`` [rad]), meaningful from failure on;
    outcome, how the path ended (None where not given).
    """

    time: np.ndarray
    penetration: np.ndarray
    lateral: np.ndarray
    obliquity: np.ndarray
    speed: np.ndarray
    failure_state: dict[str, np.ndarray] = attrs.field(factory=dict)
    outcome: Outcome | None = attrs.field(default=None, kw_only=True)

    def _parts(self) -> list[views.PathPart]:
        columns = {name: np.asarray(getattr(self, name)) for name in TRAJECTORY_FIELDS}
        return views.trajectory_parts(columns, self.outcome, list(self.failure_state))

    def __repr__(self) -> str:
        return views.trajectory_repr(self._parts())

    def _repr_html_(self) -> str:
        return views.trajectory_html(self._parts())


@attrs.frozen(repr=False)
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

    def _columns(self) -> dict[str, object]:
        return {name: getattr(self, name) for name in RESULT_FIELDS}

    def __repr__(self) -> str:
        return views.result_repr(self._columns())

    def _repr_html_(self) -> str:
        return views.result_html(self._columns())

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
    columns are ``TRAJECTORY_FIELDS`` then ``failure_<state>``; the craters' are
    ``lateral`` and ``depth`` per point and ``impact_point`` per scene
    (``CRATER_FIELDS``). ``stats`` counts the integrator's work. ``inputs``, when
    attached, are the scenes they are of (with their plate constants' declarations):
    :meth:`to_xarray` and :meth:`to_dataframe` give them as coordinates.
    """

    def __init__(
        self,
        columns: dict[str, np.ndarray],
        trajectory: Ragged | None = None,
        stats: dict[str, int] | None = None,
        craters: Ragged | None = None,
        *,
        inputs: SceneInputs | None = None,
    ) -> None:
        missing = set(RESULT_FIELDS) - set(columns)
        if missing:
            raise ValueError(f"result columns missing: {sorted(missing)}")
        self.columns = columns
        self.trajectory = trajectory
        self.stats = stats or {}
        self.craters = craters
        if inputs is not None and any(np.size(c) != len(self) for c in inputs.columns.values()):
            raise ValueError(f"the inputs attached are not of {len(self)} scenes")
        self.inputs = inputs

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
        found = [p.inputs for p in parts if p.inputs is not None]
        inputs = SceneInputs.concat(found) if len(found) == len(parts) else None
        return cls(columns, trajectory, stats, craters, inputs=inputs)

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
            inputs=None if self.inputs is None else self.inputs.take(index),
        )

    @property
    def scenes(self) -> SceneBatch | None:
        """The scenes these are the results of [SI], when they are attached
        (:meth:`~plateimpact.Simulation.run_batch` and a study's runs attach them)."""
        if self.inputs is None:
            return None
        return SceneBatch.of(dict(self.inputs.columns), len(self))

    def to_xarray(self) -> xarray.Dataset:
        """The results as an xarray Dataset over ``scene`` [SI, CF ``units``], the scenes'
        inputs as coordinates (as the archive's run file has them): every column of
        ``RESULT_FIELDS``, the outcome and plate failure as CF flags."""
        return self._table().to_xarray()

    def to_dataframe(self) -> pandas.DataFrame:
        """The results as a pandas DataFrame, one row per scene (index ``scene``), the
        inputs then the results in user units, each column named with its unit
        (``impact_obliquity_deg``, ``exit_speed_m_s``), the outcome by name; as
        ``plateimpact export --to FILE.csv`` writes a run. pandas is needed
        (``pip install 'plateimpact[review]'``)."""
        return self._table().to_dataframe()

    def _table(self) -> LabelledTable:
        return scene_table(self.inputs, len(self), [self.columns])

    def _kept(self) -> list[str]:
        kept = (("trajectories", self.trajectory), ("craters", self.craters))
        return [what for what, data in kept if data is not None]

    def __repr__(self) -> str:
        return views.batch_result_repr(len(self), self.columns, self.inputs, self._kept())

    def _repr_html_(self) -> str:
        return views.batch_result_html(len(self), self.columns, self.inputs, self._kept())

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
        outcome = Outcome(int(self.columns["outcome"][i]))
        return Trajectory(
            **{k: row[k] for k in TRAJECTORY_FIELDS}, failure_state=state, outcome=outcome
        )

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
