"""What the boundary finder found along one line, and the named limits read from it.

Positions are SI: impact speed [m/s] along a speed line, impact obliquity [rad] along an
obliquity line. ``to_json`` gives user units, with the unit in every key.
"""

from __future__ import annotations

import math
from typing import Any

import attrs

from ..base.parameters import Parameter
from ..model.results import Outcome
from .regimes import Regime

#: The two kinds of line: along impact speed at a fixed obliquity, or along obliquity at
#: a fixed speed.
SPEED, OBLIQUITY = "impact_speed", "impact_obliquity"
_DEG = math.pi / 180.0
#: The named limits of a line along each axis (the properties of :class:`LimitLine`),
#: declared: what each is and its unit.
NAMED_LIMITS: dict[str, tuple[Parameter, ...]] = {
    SPEED: (
        Parameter("ballistic_limit", "lowest speed above which every scene perforates", "m/s"),
        Parameter(
            "lowest_perforation", "lowest perforating speed, if below the ballistic limit", "m/s"
        ),
        Parameter("ricochet_limit", "highest speed at which the sphere ricochets", "m/s"),
    ),
    OBLIQUITY: (
        Parameter(
            "critical_ricochet_obliquity",
            "lowest obliquity above which every scene ricochets",
            "rad",
            display_unit="deg",
            scale=_DEG,
        ),
    ),
}


def _user(axis: str, value: float | None) -> float | None:
    """``value`` [SI] on ``axis`` in user units (m/s or degrees); None stays None."""
    if value is None:
        return None
    if axis == OBLIQUITY:  # 15, not 14.999999999999998 after the round trip through rad
        return float(f"{float(value) / _DEG:.12g}")
    return float(value)


def unit_suffix(axis: str) -> str:
    return "deg" if axis == OBLIQUITY else "m_s"


@attrs.frozen
class Band:
    """A run of one regime along a line, from ``start`` to ``end`` [m/s or rad]."""

    regime: Regime
    start: float
    end: float

    @property
    def width(self) -> float:
        return self.end - self.start


@attrs.frozen
class Boundary:
    """Where the regime changes from ``below`` to ``above``: a scene at ``low`` ends in
    ``below``, one at ``high`` in ``above``, and high − low <= the tolerance. ``at`` is
    the midpoint, within half the tolerance of the change."""

    low: float
    high: float
    below: Regime
    above: Regime

    @property
    def at(self) -> float:
        return 0.5 * (self.low + self.high)


@attrs.frozen
class LimitLine:
    """The bands along one line: ``axis`` (``impact_speed`` or ``impact_obliquity``)
    from ``start`` to ``end`` at the other coordinate fixed at ``fixed``."""

    axis: str
    fixed: float
    start: float
    end: float
    boundaries: tuple[Boundary, ...]
    first: Regime

    @property
    def bands(self) -> tuple[Band, ...]:
        """The bands in order; each ends where the next starts (at a boundary's ``at``)."""
        edges = [self.start, *(b.at for b in self.boundaries), self.end]
        regimes = [self.first, *(b.above for b in self.boundaries)]
        return tuple(
            Band(r, lo, hi) for r, lo, hi in zip(regimes, edges[:-1], edges[1:], strict=True)
        )

    def _top_run(self, outcome: Outcome) -> float | None:
        """Where the run of ``outcome`` bands that reaches the end of the line starts;
        None if the end is another outcome or the run fills the line (no boundary)."""
        bands = self.bands
        k = len(bands)
        while k and bands[k - 1].regime.outcome is outcome:
            k -= 1
        return bands[k].start if 0 < k < len(bands) else None

    @property
    def ballistic_limit(self) -> float | None:
        """Along speed: the lowest speed above which every scene perforates [m/s]; None
        if the line's highest speed does not perforate or its lowest already does."""
        return self._top_run(Outcome.PERFORATION) if self.axis == SPEED else None

    @property
    def lowest_perforation(self) -> float | None:
        """Along speed: the lowest perforating speed [m/s], when the line has a
        perforation band that does not start at the line's start."""
        if self.axis != SPEED:
            return None
        found = [b for b in self.bands if b.regime.outcome is Outcome.PERFORATION]
        return found[0].start if found and found[0].start > self.start else None

    @property
    def ricochet_limit(self) -> float | None:
        """Along speed: the highest speed at which the sphere ricochets [m/s], off an
        intact or a failed plate; None if it still ricochets at the line's end."""
        if self.axis != SPEED:
            return None
        found = [b for b in self.bands if b.regime.outcome is Outcome.RICOCHET]
        return found[-1].end if found and found[-1].end < self.end else None

    @property
    def critical_ricochet_obliquity(self) -> float | None:
        """Along obliquity: the lowest obliquity above which every scene ricochets
        [rad]; None if the line's highest obliquity does not ricochet or its lowest
        already does."""
        return self._top_run(Outcome.RICOCHET) if self.axis == OBLIQUITY else None

    def to_json(self) -> dict[str, Any]:
        """The line in user units (the ``lines`` entries of ``plateimpact limits
        --json``)."""
        unit = unit_suffix(self.axis)
        out: dict[str, Any] = {}
        if self.axis == SPEED:
            out["obliquity_deg"] = _user(OBLIQUITY, self.fixed)
        else:
            out["speed_m_s"] = _user(SPEED, self.fixed)
        out["bands"] = [
            {
                **band.regime.to_json(),
                f"from_{unit}": _user(self.axis, band.start),
                f"to_{unit}": _user(self.axis, band.end),
            }
            for band in self.bands
        ]
        out["boundaries"] = [
            {
                f"at_{unit}": _user(self.axis, b.at),
                f"low_{unit}": _user(self.axis, b.low),
                f"high_{unit}": _user(self.axis, b.high),
                "below": b.below.label,
                "above": b.above.label,
            }
            for b in self.boundaries
        ]
        if self.axis == SPEED:
            out["ballistic_limit_m_s"] = self.ballistic_limit
            out["lowest_perforation_m_s"] = self.lowest_perforation
            out["ricochet_limit_m_s"] = self.ricochet_limit
        else:
            out["critical_ricochet_obliquity_deg"] = _user(
                OBLIQUITY, self.critical_ricochet_obliquity
            )
        return out
