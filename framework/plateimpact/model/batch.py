"""A batch of scenes as columns of numpy arrays: what integrators and plug-ins work on.

Plug-ins never see :class:`~plateimpact.model.scene.Scene` objects inside the step loop; they
see a :class:`SceneBatch`, whose columns are arrays with one entry per scene.
"""

from __future__ import annotations

import reprlib
from collections.abc import Iterable, Iterator, Mapping
from typing import TYPE_CHECKING

import numpy as np

from ..base.errors import ParameterError
from ..base.parameters import Parameter, check_instance
from . import views
from .bodies import Plate, Sphere, check_density
from .fields import CORE_COLUMNS
from .scene import IMPACT_OBLIQUITY, IMPACT_SPEED, Scene
from .tables import SceneInputs, scene_table

if TYPE_CHECKING:
    import pandas
    import xarray


def _numbers(name: str, values: object, *, flat: bool = True) -> np.ndarray:
    """``values`` as a float array (1-D if ``flat``); ParameterError naming the column
    for anything that is not numbers (text, ragged rows, an int beyond 1.8e308)."""
    try:
        array = np.ascontiguousarray(values, dtype=float)
    except (TypeError, ValueError, OverflowError):
        raise ParameterError(name, f"{name} must be numbers, got {reprlib.repr(values)}") from None
    return array.reshape(-1) if flat else array


def _batches(batches: Iterable[SceneBatch]) -> list[SceneBatch]:
    try:
        found = list(batches)
    except TypeError:
        found = [batches]  # type: ignore[list-item]  # reported below
    for batch in found:
        if not isinstance(batch, SceneBatch):
            raise ParameterError("batches", f"expected SceneBatch objects, got {batch!r:.80}")
    return found


def check_chunk_size(chunk_size: object) -> None:
    """Scenes per chunk must be a positive integer."""
    if not (isinstance(chunk_size, int | np.integer) and chunk_size >= 1):
        raise ParameterError(
            "chunk_size", f"chunk_size must be an integer >= 1, got {chunk_size!r}"
        )


def _grid_axes(
    sphere: Sphere, plate: Plate, speeds: object, obliquities: object
) -> tuple[np.ndarray, np.ndarray]:
    """A grid's checked axes: speeds [m/s] and obliquities [rad] as float arrays."""
    check_instance("sphere", sphere, Sphere)
    check_instance("plate", plate, Plate)
    speeds, obliquities = (
        _numbers(IMPACT_SPEED.name, speeds),
        _numbers(IMPACT_OBLIQUITY.name, obliquities),
    )
    IMPACT_SPEED.check(speeds)
    IMPACT_OBLIQUITY.check(obliquities)
    return speeds, obliquities


class SceneBatch:
    """Per-scene parameters as 1-D float arrays of equal length.

    Columns are read as attributes (``batch.radius``): ``CORE_COLUMNS``, then the
    plate constants. Inside the step loop a plug-in sees its own view of the bound batch
    (:class:`~plateimpact.model.binding.BoundBatch`): the core columns, the plate constants it
    declared and the per-scene columns it prepared.
    """

    __slots__ = ("_columns", "size")

    _columns: dict[str, np.ndarray]
    size: int

    def __init__(self, columns: Mapping[str, object], *, validate: bool = True) -> None:
        if not isinstance(columns, Mapping):
            raise ParameterError(
                "columns", f"a batch takes a mapping of column names to arrays, got {columns!r:.80}"
            )
        arrays = {k: _numbers(k, c) for k, c in columns.items()}
        sizes = {a.size for a in arrays.values()}
        if len(sizes) > 1:
            raise ParameterError("columns", f"batch columns differ in length: {sorted(sizes)}")
        if validate:
            for name, declared in CORE_COLUMNS.items():
                if name not in arrays:
                    raise ParameterError(name, f"batch column {name!r} is missing")
                declared.check(arrays[name])
            check_density(arrays["radius"], arrays["mass"])
            for name, values in arrays.items():
                if name not in CORE_COLUMNS and np.isnan(values).any():
                    scene = int(np.flatnonzero(np.isnan(values))[0])
                    raise ParameterError(name, f"{name} must be a number, got nan (scene {scene})")
        self._columns = arrays
        self.size = sizes.pop() if sizes else 0

    @classmethod
    def of(cls, columns: dict[str, np.ndarray], size: int) -> SceneBatch:
        """A batch of arrays already checked (no copy, no validation): for the core's own
        views and subsets."""
        new = object.__new__(cls)
        new._columns = columns
        new.size = size
        return new

    @classmethod
    def from_scenes(cls, scenes: Iterable[Scene]) -> SceneBatch:
        """Columns from validated :class:`Scene` objects, whose plates must have the same
        constants."""
        try:
            scenes = list(scenes)
        except TypeError:
            scenes = [scenes]  # type: ignore[list-item]  # reported below
        for i, scene in enumerate(scenes):
            check_instance(f"scene {i}", scene, Scene)
        names = [tuple(k for k, _ in s.plate.constants) for s in scenes]
        for i, found in enumerate(names):
            if found != names[0]:
                raise ParameterError(
                    "constants",
                    f"the plates of a batch must have the same constants: scene {i} has "
                    f"{', '.join(found) or 'none'}, scene 0 has {', '.join(names[0]) or 'none'}",
                )
        columns: dict[str, list[float]] = {
            "radius": [s.sphere.radius for s in scenes],
            "mass": [s.sphere.mass for s in scenes],
            "thickness": [s.plate.thickness for s in scenes],
            "impact_speed": [s.impact_speed for s in scenes],
            "impact_obliquity": [s.impact_obliquity for s in scenes],
        }
        for k, name in enumerate(names[0] if scenes else ()):
            columns[name] = [s.plate.constants[k][1] for s in scenes]
        return cls(columns, validate=False)

    @classmethod
    def grid(
        cls,
        sphere: Sphere,
        plate: Plate,
        speeds: np.ndarray | Iterable[float],
        obliquities: np.ndarray | Iterable[float],
    ) -> SceneBatch:
        """Every (obliquity, speed) pair for one sphere and plate, obliquity-major.

        Parameters: speeds [m/s]; obliquities [rad]. Built as arrays, without a Scene
        object per point, so that a 10,000-scene sweep costs no Python loop.
        """
        speeds, obliquities = _grid_axes(sphere, plate, speeds, obliquities)
        obl, spd = np.meshgrid(obliquities, speeds, indexing="ij")
        return cls._of_impacts(sphere, plate, spd.ravel(), obl.ravel())

    @classmethod
    def grid_chunks(
        cls,
        sphere: Sphere,
        plate: Plate,
        speeds: np.ndarray | Iterable[float],
        obliquities: np.ndarray | Iterable[float],
        chunk_size: int,
    ) -> Iterator[SceneBatch]:
        """The scenes of :meth:`grid` (``speeds`` [m/s] × ``obliquities`` [rad]), in its
        order and with the same values, as batches
        of ``chunk_size`` scenes (the last one shorter), each built only when asked for:
        memory holds one chunk, however large the grid. Checked before the first."""
        speeds, obliquities = _grid_axes(sphere, plate, speeds, obliquities)
        check_chunk_size(chunk_size)
        return cls._grid_chunks(sphere, plate, speeds, obliquities, int(chunk_size))

    @classmethod
    def _grid_chunks(
        cls, sphere: Sphere, plate: Plate, speeds: np.ndarray, obliquities: np.ndarray, size: int
    ) -> Iterator[SceneBatch]:
        total = speeds.size * obliquities.size
        for start in range(0, total, size):
            row, column = np.divmod(np.arange(start, min(start + size, total)), speeds.size)
            yield cls._of_impacts(sphere, plate, speeds[column], obliquities[row])

    @classmethod
    def _of_impacts(
        cls, sphere: Sphere, plate: Plate, speeds: np.ndarray, obliquities: np.ndarray
    ) -> SceneBatch:
        """One sphere and plate at the checked impacts ``speeds`` [m/s], ``obliquities``
        [rad] (equal lengths)."""
        n = speeds.size
        columns = {
            "radius": np.full(n, sphere.radius),
            "mass": np.full(n, sphere.mass),
            "thickness": np.full(n, plate.thickness),
            "impact_speed": speeds,
            "impact_obliquity": obliquities,
        }
        columns.update({name: np.full(n, value) for name, value in plate.constants})
        return cls.of(columns, n)

    @classmethod
    def concat(cls, batches: Iterable[SceneBatch]) -> SceneBatch:
        """One batch holding the scenes of ``batches`` in order (same columns required)."""
        batches = _batches(batches)
        names = list(batches[0]._columns) if batches else list(CORE_COLUMNS)
        for batch in batches:
            if set(batch._columns) != set(names):
                raise ParameterError(
                    "columns",
                    "batches to concatenate must have the same columns, got "
                    f"{', '.join(sorted(batch._columns))} and {', '.join(sorted(names))}",
                )
        columns = {k: np.concatenate([b._columns[k] for b in batches]) for k in names}
        if not batches:
            columns = {k: np.zeros(0) for k in names}
        return cls.of(columns, sum(b.size for b in batches))

    def __getattr__(self, name: str) -> np.ndarray:
        if name.startswith("_"):  # e.g. _columns itself while unpickling: not a column
            raise AttributeError(name)
        try:
            return self._columns[name]
        except KeyError:
            raise AttributeError(
                f"this batch has no column {name!r} (columns: {', '.join(self._columns)}); "
                "a plug-in sees only the plate constants it declares in plate_constants"
            ) from None

    def __getstate__(self) -> tuple[dict[str, np.ndarray], int]:
        return self._columns, self.size

    def __setstate__(self, state: tuple[dict[str, np.ndarray], int]) -> None:
        self._columns, self.size = state

    def __len__(self) -> int:
        return self.size

    @property
    def columns(self) -> dict[str, np.ndarray]:
        """The columns by name (a new dict; the arrays are shared)."""
        return dict(self._columns)

    @property
    def constant_names(self) -> list[str]:
        """The plate constants among the columns."""
        return [name for name in self._columns if name not in CORE_COLUMNS]

    def with_columns(self, **extra: object) -> SceneBatch:
        """A batch with more (or replaced) columns, each broadcast to the batch size."""
        merged = dict(self._columns)
        for name, values in extra.items():
            array = _numbers(name, values, flat=False)
            try:
                merged[name] = np.broadcast_to(array, (self.size,))
            except ValueError:  # shapes that do not broadcast
                raise ParameterError(
                    name, f"column {name!r} has {array.size} values for {self.size} scenes"
                ) from None
        return SceneBatch(merged, validate=False)

    def take(self, index: np.ndarray) -> SceneBatch:
        """The sub-batch of the scenes at ``index`` (integer or boolean array)."""
        columns = {k: c[index] for k, c in self._columns.items()}
        size = next(iter(columns.values())).size if columns else 0
        return SceneBatch.of(columns, size)

    def to_xarray(self, constants: Mapping[str, Parameter] | None = None) -> xarray.Dataset:
        """The scenes as an xarray Dataset of coordinates over ``scene`` [SI, CF
        ``units``]; ``constants`` declares the plate constants' units
        (``simulation.model.plate_constants()``, ``registry.plate_constants``): one not
        declared is a number of unit 1 whose description says so."""
        return scene_table(SceneInputs(self._columns, constants or {}), self.size).to_xarray()

    def to_dataframe(self, constants: Mapping[str, Parameter] | None = None) -> pandas.DataFrame:
        """The scenes as a pandas DataFrame, one row per scene, in user units with the unit
        in each column's name (``impact_speed_m_s``); ``constants`` as for
        :meth:`to_xarray`. pandas is needed (``pip install 'plateimpact[review]'``)."""
        inputs = SceneInputs(self._columns, constants or {})
        return scene_table(inputs, self.size).to_dataframe()

    def __repr__(self) -> str:
        return views.scenes_repr(self.size, SceneInputs(self._columns))

    def _repr_html_(self) -> str:
        return views.scenes_html(self.size, SceneInputs(self._columns))
