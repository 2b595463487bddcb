"""What every plug-in shares: its name, version, declarations and settings.

A plug-in declares what it needs from the plate (:attr:`Plugin.plate_constants`) and
what it computes once per batch (:attr:`Plugin.columns`); its settings are its attrs
fields, declared with :meth:`Parameter.field <plateimpact.base.parameters.Parameter.field>`.
The core validates and namespaces all of it, so a plug-in never sees, and never
overwrites, another's columns.
"""

from __future__ import annotations

from typing import Any, ClassVar

import attrs
import numpy as np

from ..base.parameters import Parameter, declared_settings
from .batch import SceneBatch


@attrs.frozen
class Column:
    """A per-scene column a plug-in computes once per batch in ``prepare``.

    ``name`` is how the plug-in reads it back (``batch.failure_plane_depth``); ``unit``
    [SI] and ``description`` document it.
    """

    name: str
    unit: str
    description: str


class Plugin:
    """Base of :class:`~plateimpact.ResistanceLaw`, :class:`~plateimpact.FailureModel`
    and :class:`~plateimpact.Integrator`.

    Attributes
    ----------
    name : str
        The name users select it by.
    version : str
        Recorded in archives: change it when results change.
    plate_constants : tuple of Parameter
        The plate constants it reads (``batch.a``): name, SI unit, range, default, flag.
        Two plug-ins may share a constant only through equal declarations (reuse the
        object, e.g. ``plateimpact_plugins.STRENGTH_A``).
    columns : tuple of Column
        The per-scene columns its :meth:`prepare` returns.
    kernel_columns : tuple of str
        The columns of its view its compiled kernels read, in order (its row of
        :meth:`kernel_constants`; :mod:`plateimpact.model.kernels`).
    """

    name: ClassVar[str]
    version: ClassVar[str] = "1"
    plate_constants: ClassVar[tuple[Parameter, ...]] = ()
    columns: ClassVar[tuple[Column, ...]] = ()
    kernel_columns: ClassVar[tuple[str, ...]] = ()

    @classmethod
    def setting_declarations(cls) -> dict[str, Parameter]:
        """Its settings (attrs fields) by name, each with its declaration."""
        return declared_settings(cls)

    def settings(self) -> dict[str, Any]:
        """Every setting, as JSON values [SI], for outputs and archives: all its attrs
        fields, so nothing set is ever missing from a record."""
        return {
            name: declared.json_value(getattr(self, name))
            for name, declared in self.setting_declarations().items()
        }

    def prepare(self, scenes: SceneBatch) -> dict[str, np.ndarray]:
        """The per-scene columns declared in ``columns``, by name, computed once per batch
        before any step from this plug-in's view of the scenes (default: none)."""
        return {}

    def kernel_constants(self, scenes: SceneBatch) -> np.ndarray:
        """What its compiled kernels read per scene, shape (k, n) [SI]: by default the
        columns ``kernel_columns`` names, from this plug-in's view of the scenes; a
        plug-in whose kernels also read settings adds them as rows."""
        size = scenes.size
        rows = [np.broadcast_to(getattr(scenes, name), (size,)) for name in self.kernel_columns]
        if not rows:
            return np.zeros((0, scenes.size))
        return np.ascontiguousarray(np.stack(rows), dtype=float)
