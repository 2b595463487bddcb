"""A batch of scenes as columns of numpy arrays: what integrators and plug-ins work on.

Plug-ins never see :class:`~plateimpact.scene.Scene` objects inside the step loop; they
see a :class:`SceneBatch`, whose columns are arrays with one entry per scene.
"""

from __future__ import annotations

from collections.abc import Iterable, Mapping

import numpy as np

from . import validation as v
from .bodies import Plate, Sphere
from .scene import Scene

#: The columns every batch has, with their range [SI units].
BASE_COLUMNS: dict[str, v.Range] = {
    "radius": v.RADIUS,  # Rs [m]
    "mass": v.MASS,  # m [kg]
    "thickness": v.THICKNESS,  # T [m]
    "a": v.STRENGTH_A,  # [N/m²]
    "b": v.DENSITY_B,  # [kg/m³]
    "critical_penetration": v.CRITICAL_PENETRATION,  # P* of the plate [m]
    "failure_angle": v.FAILURE_ANGLE,  # α* [rad]
    "impact_speed": v.IMPACT_SPEED,  # Vs [m/s]
    "impact_obliquity": v.IMPACT_OBLIQUITY,  # θs [rad]
}


class SceneBatch:
    """Per-scene parameters as 1-D float arrays of equal length.

    Columns are read as attributes (``batch.radius``). Besides :data:`BASE_COLUMNS`, a
    model adds the columns its plug-ins prepare once per batch (``onset_penetration``,
    ``failure_plane_depth``, ...), so that no derived quantity is recomputed per step.
    """

    __slots__ = ("_columns", "size")

    def __init__(self, columns: Mapping[str, np.ndarray], *, validate: bool = True) -> None:
        arrays = {k: np.ascontiguousarray(c, dtype=float).reshape(-1) for k, c in columns.items()}
        sizes = {a.size for a in arrays.values()}
        if len(sizes) > 1:
            raise ValueError(f"batch columns differ in length: {sorted(sizes)}")
        if validate:
            for name, allowed in BASE_COLUMNS.items():
                if name not in arrays:
                    raise ValueError(f"batch column {name!r} is missing")
                allowed.check(name, arrays[name])
        self._columns = arrays
        self.size = sizes.pop() if sizes else 0

    @classmethod
    def from_scenes(cls, scenes: Iterable[Scene]) -> SceneBatch:
        """Columns from validated :class:`Scene` objects."""
        scenes = list(scenes)
        return cls(
            {
                "radius": [s.sphere.radius for s in scenes],
                "mass": [s.sphere.mass for s in scenes],
                "thickness": [s.plate.thickness for s in scenes],
                "a": [s.plate.a for s in scenes],
                "b": [s.plate.b for s in scenes],
                "critical_penetration": [s.plate.critical_penetration for s in scenes],
                "failure_angle": [s.plate.failure_angle for s in scenes],
                "impact_speed": [s.impact_speed for s in scenes],
                "impact_obliquity": [s.impact_obliquity for s in scenes],
            },
            validate=False,
        )

    @classmethod
    def grid(
        cls,
        sphere: Sphere,
        plate: Plate,
        speeds: np.ndarray,
        obliquities: np.ndarray,
    ) -> SceneBatch:
        """Every (obliquity, speed) pair for one sphere and plate, obliquity-major.

        Parameters: speeds [m/s]; obliquities [rad]. Built as arrays, without a Scene
        object per point, so that a 10,000-scene sweep costs no Python loop.
        """
        speeds = np.asarray(speeds, dtype=float).reshape(-1)
        obliquities = np.asarray(obliquities, dtype=float).reshape(-1)
        v.IMPACT_SPEED.check("impact_speed", speeds)
        v.IMPACT_OBLIQUITY.check("impact_obliquity", obliquities)
        obl, spd = np.meshgrid(obliquities, speeds, indexing="ij")
        n = spd.size
        return cls(
            {
                "radius": np.full(n, sphere.radius),
                "mass": np.full(n, sphere.mass),
                "thickness": np.full(n, plate.thickness),
                "a": np.full(n, plate.a),
                "b": np.full(n, plate.b),
                "critical_penetration": np.full(n, plate.critical_penetration),
                "failure_angle": np.full(n, plate.failure_angle),
                "impact_speed": spd.ravel(),
                "impact_obliquity": obl.ravel(),
            },
            validate=False,
        )

    @classmethod
    def concat(cls, batches: Iterable[SceneBatch]) -> SceneBatch:
        """One batch holding the scenes of ``batches`` in order (same columns required)."""
        batches = list(batches)
        names = set(batches[0]._columns) if batches else set(BASE_COLUMNS)
        if any(set(b._columns) != names for b in batches):
            raise ValueError("batches to concatenate must have the same columns")
        return cls(
            {k: np.concatenate([b._columns[k] for b in batches]) for k in names}
            if batches
            else {k: np.zeros(0) for k in names},
            validate=False,
        )

    def __getattr__(self, name: str) -> np.ndarray:
        if name.startswith("_"):  # e.g. _columns itself while unpickling: not a column
            raise AttributeError(name)
        try:
            return self._columns[name]
        except KeyError:
            raise AttributeError(f"SceneBatch has no column {name!r}") from None

    def __len__(self) -> int:
        return self.size

    @property
    def columns(self) -> Mapping[str, np.ndarray]:
        """Read-only view of the columns."""
        return dict(self._columns)

    def with_columns(self, **extra: np.ndarray) -> SceneBatch:
        """A batch with more (or replaced) columns, each broadcast to the batch size."""
        merged = dict(self._columns)
        for name, values in extra.items():
            merged[name] = np.broadcast_to(np.asarray(values, dtype=float), (self.size,))
        return SceneBatch(merged, validate=False)

    def take(self, index: np.ndarray) -> SceneBatch:
        """The sub-batch of the scenes at ``index`` (integer or boolean array)."""
        new = object.__new__(SceneBatch)
        new._columns = {k: c[index] for k, c in self._columns.items()}
        new.size = next(iter(new._columns.values())).size if new._columns else 0
        return new
