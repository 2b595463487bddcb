"""Rows of scenes and results as labelled tables: an xarray Dataset [SI, CF attributes]
and a pandas DataFrame [user units, the unit in each column's name], both made from one
:class:`LabelledTable` of declared columns, so that the two say the same thing.

The Dataset is what the archive's run files hold (docs/archive.md): SI values, CF
``units``, ``long_name`` and ``description`` on every variable, ``flag_values`` and
``flag_meanings`` on the integer-coded ones, the scenes' inputs as coordinates. The
DataFrame is the tidy table ``plateimpact export --to FILE.csv`` writes: one row per
scene, columns named with their unit (``impact_speed_m_s``, ``exit_obliquity_deg``),
the outcome by name; ``frame.attrs["units"]`` gives each column's unit.

xarray and pandas are imported only here, when a table is asked for.
"""

from __future__ import annotations

from collections.abc import Mapping, Sequence
from typing import TYPE_CHECKING, Any

import attrs
import numpy as np

from ..base.extras import REVIEW, optional
from ..base.parameters import Parameter
from .fields import CORE_COLUMNS, RESULT_FIELDS, Outcome

if TYPE_CHECKING:
    import pandas
    import xarray

#: The CF version the tables and files follow.
CONVENTIONS = "CF-1.11"
#: CF flags of the integer-coded results.
FLAGS: dict[str, tuple[list[int], str]] = {
    "outcome": ([int(o) for o in Outcome], " ".join(o.label for o in Outcome)),
    "plate_failed": ([0, 1], "intact failed"),
}
SCENE = "scene"
#: The index of a scene in its batch or study, and its plate's label.
SCENE_INDEX = Parameter(SCENE, "the scene's index in its study, from 0", kind=int)
PLATE = Parameter("plate", "the plate's label (a preset name, or the study's own)", kind=str)
VARIANT = Parameter("variant", "the run's name: a model variant of the study", kind=str)

#: A column: its dimensions, its values [SI] and its declaration.
Column = tuple[tuple[str, ...], np.ndarray, Parameter]


def long_name(declared: Parameter) -> str:
    return declared.name.replace("_", " ")


def cf_attributes(declared: Parameter) -> dict[str, Any]:
    """A variable's CF attributes: ``long_name``, ``description``, the flags of an
    integer code, and the SI ``units`` of a number (none for a label, or for a number
    whose unit is not known: :func:`column_declaration`)."""
    attributes: dict[str, Any] = {"long_name": long_name(declared)}
    attributes["description"] = declared.description
    if declared.name in FLAGS:
        attributes["flag_values"] = np.array(FLAGS[declared.name][0], dtype=np.int8)
        attributes["flag_meanings"] = FLAGS[declared.name][1]
    if declared.kind is not str and declared.unit:
        attributes["units"] = declared.unit
    return attributes


def column_declaration(name: str, constants: Mapping[str, Parameter]) -> Parameter:
    """What a scene column is: a core column, else a plate constant ``constants``
    declares, else a number of unknown unit (``unit`` empty; its description says so)."""
    found = CORE_COLUMNS.get(name) or constants.get(name)
    undeclared = f"plate constant {name} (no plug-in given declares it: unit unknown)"
    return found or Parameter(name, undeclared, unit="")


@attrs.frozen(eq=False)
class SceneInputs:
    """The scenes a result's rows are of: their columns [SI] (a batch's), the
    declarations of their plate constants (the plug-ins' that read them), and in a study
    each scene's plate label."""

    columns: Mapping[str, np.ndarray]
    constants: Mapping[str, Parameter] = attrs.field(factory=dict)
    plate_labels: tuple[str, ...] | None = None

    def declared(self, name: str) -> Parameter:
        return column_declaration(name, self.constants)

    def take(self, index: np.ndarray) -> SceneInputs:
        """The inputs of the scenes at ``index``."""
        labels = self.plate_labels
        return SceneInputs(
            {k: np.asarray(v)[index] for k, v in self.columns.items()},
            self.constants,
            None if labels is None else tuple(labels[i] for i in np.asarray(index, dtype=int)),
        )

    @classmethod
    def concat(cls, parts: Sequence[SceneInputs]) -> SceneInputs:
        """The inputs of ``parts`` in order (the chunks of one run)."""
        labels = [p.plate_labels for p in parts]
        joined = None if None in labels else tuple(x for part in labels for x in part or ())
        return cls(
            {k: np.concatenate([p.columns[k] for p in parts]) for k in parts[0].columns},
            parts[0].constants,
            joined,
        )


def _stored(values: np.ndarray) -> np.ndarray:
    """Values as a table holds them: a flag as int8, as the run files do; labels as
    objects."""
    values = np.asarray(values)
    if values.dtype == bool:
        return values.astype(np.int8)
    return values.astype(object) if values.dtype.kind in "US" else values


def _user_values(declared: Parameter, values: np.ndarray) -> Any:
    """A column of the DataFrame: a number in the user's unit, a flag as bool, the
    outcome by name."""
    if declared.kind is bool:
        return values.astype(bool)
    if declared.name == "outcome":
        import pandas as pd  # noqa: PLC0415 (checked by to_dataframe)

        labels = [o.label for o in Outcome]
        return pd.Categorical.from_codes(np.asarray(values, dtype=np.int64) - 1, labels)
    if declared.kind is float:
        return np.asarray(values, dtype=float) / declared.scale
    return values


@attrs.frozen(eq=False)
class LabelledTable:
    """Declared columns over named dimensions (``dimensions``, outermost first, the
    DataFrame's index): the one source of :meth:`to_xarray` and :meth:`to_dataframe`."""

    dimensions: tuple[str, ...]
    coordinates: dict[str, Column]
    variables: dict[str, Column]
    attributes: Mapping[str, object] = attrs.field(factory=dict)

    def to_xarray(self) -> xarray.Dataset:
        """A Dataset [SI], every variable and coordinate with its CF attributes."""
        xr = optional("xarray", "to_xarray", REVIEW)

        def entries(columns: dict[str, Column]) -> dict[str, Any]:
            return {
                name: (dims, _stored(values), cf_attributes(declared))
                for name, (dims, values, declared) in columns.items()
            }

        return xr.Dataset(
            entries(self.variables),
            entries(self.coordinates),
            attrs={"Conventions": CONVENTIONS, **self.attributes},
        )

    def to_dataframe(self) -> pandas.DataFrame:
        """The Dataset as a tidy DataFrame in user units: one row per cell of its
        dimensions (their keys the index), each column named with its unit (the
        column's ``key``: ``impact_speed_m_s``); ``attrs["units"]``: the unit of each
        column whose unit is known ("1" for a pure number)."""
        pd = optional("pandas", "to_dataframe", REVIEW)
        flat = self.to_xarray().to_dataframe().reset_index()
        declared = {name: column[2] for name, column in self.coordinates.items()}
        declared.update({name: column[2] for name, column in self.variables.items()})
        frame = pd.DataFrame(
            {d.key: _user_values(d, flat[name].to_numpy()) for name, d in declared.items()}
        )
        frame = frame.set_index([declared[d].key for d in self.dimensions])
        frame.attrs["units"] = {
            d.key: d.user_unit for d in declared.values() if d.kind is not str and d.unit
        }
        return frame


def scene_table(
    inputs: SceneInputs | None,
    size: int,
    runs: Sequence[Mapping[str, np.ndarray]] = (),
    variants: Sequence[str] | None = None,
    attributes: Mapping[str, object] | None = None,
) -> LabelledTable:
    """``size`` scenes as rows: their inputs as coordinates over ``scene`` (as a run file
    has them), and the result columns of ``runs``: of the one run over ``scene``, or
    with ``variants`` (one name per run) over (variant, scene)."""
    scene = (SCENE,)
    coordinates: dict[str, Column] = {SCENE: (scene, np.arange(size, dtype=np.int64), SCENE_INDEX)}
    if inputs is not None:
        for name, values in inputs.columns.items():
            coordinates[name] = (scene, np.asarray(values), inputs.declared(name))
        if inputs.plate_labels is not None:
            coordinates[PLATE.name] = (scene, np.array(inputs.plate_labels, dtype=object), PLATE)
    dimensions: tuple[str, ...] = scene
    if variants is not None:
        dimensions = (VARIANT.name, SCENE)
        coordinates[VARIANT.name] = ((VARIANT.name,), np.array(variants, dtype=object), VARIANT)
    variables: dict[str, Column] = {}
    for name, declared in RESULT_FIELDS.items():
        if variants is not None:
            stacked = [np.asarray(run[name]) for run in runs]
            values = np.stack(stacked) if stacked else np.empty((0, size))
            variables[name] = (dimensions, values, declared)
        elif runs:
            variables[name] = (dimensions, np.asarray(runs[0][name]), declared)
    return LabelledTable(dimensions, coordinates, variables, dict(attributes or {}))
