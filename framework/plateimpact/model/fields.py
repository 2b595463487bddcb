"""What the columns of a batch and of its results are: the outcome codes, and the
declaration (:class:`~plateimpact.base.parameters.Parameter`: name, unit, description) of
every scene column every batch has, every result column, and the columns of recorded
trajectories and crater sections. Archives, CSV headers, JSON keys, reprs and labelled
tables (:mod:`.tables`) all take their names and units from here."""

from __future__ import annotations

import enum

from ..base.parameters import Parameter
from ..base.units import deg, mm
from .bodies import MASS, RADIUS, THICKNESS
from .scene import IMPACT_OBLIQUITY, IMPACT_SPEED

#: The columns every batch has, whatever the model: the sphere, the plate's thickness
#: and the impact. Any other column is a plate constant (``a``, ``critical_penetration``,
#: ...), whose facts belong to the plug-in that declares it.
CORE_COLUMNS: dict[str, Parameter] = {
    p.name: p for p in (RADIUS, MASS, THICKNESS, IMPACT_SPEED, IMPACT_OBLIQUITY)
}


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
