"""The V50 ballistic limit of MIL-STD-662F ("V50 ballistic test for armor").

The standard's V50 is the mean of an equal number of the highest partial-penetration and
the lowest complete-penetration velocities that lie within a stated velocity span: at
least two of each, and four-, six- and ten-round limits (2, 3 or 5 of each) are the ones
in use. The span allowed depends on the armour and the test; 38.1 m/s (125 ft/s) is a
common one and the default here. Partial penetration is a shot that did not perforate,
complete penetration one that did.

By default the most rounds the shots allow within the span are used (ten, else six, else
four); a ``count`` given is used or refused. When the shots do not meet the standard's
conditions the estimate is refused in one line saying why and what to fire, rather than
computed from shots the standard would not take.
"""

from __future__ import annotations

from typing import Any

import attrs
import numpy as np

from ..base.errors import ParameterError, V50Error
from ..storage.shots import Shots
from . import views
from .likelihood import SHOTS, go_no_go

#: Shots of each outcome the standard averages (four-, six- and ten-round limits).
COUNTS = (2, 3, 5)
#: The velocity span within which the shots averaged must lie by default [m/s] (125 ft/s).
DEFAULT_SPREAD = 125 * 0.3048
#: The spans accepted [m/s].
SPREAD_RANGE = (0.01, 1000.0)


@attrs.frozen(eq=False, repr=False)
class MilStd662F:
    """A MIL-STD-662F V50 [m/s]: the mean of the ``count`` highest partial penetrations
    (``partial_speeds_m_s``, fastest first) and the ``count`` lowest complete
    penetrations (``complete_speeds_m_s``, slowest first). ``spread_m_s`` is the span of
    those 2 × count speeds, at most ``spread_allowed_m_s``; ``used`` the indices of those
    shots in the arrays given; ``shots`` how many shots there were (weights counted)."""

    v50_m_s: float
    count: int
    spread_m_s: float
    spread_allowed_m_s: float
    partial_speeds_m_s: tuple[float, ...]
    complete_speeds_m_s: tuple[float, ...]
    used: tuple[int, ...]
    shots: int

    @property
    def rounds(self) -> int:
        """The shots averaged (a 4-, 6- or 10-round ballistic limit)."""
        return 2 * self.count

    def __repr__(self) -> str:
        return views.mil_std_repr(self)

    def _repr_html_(self) -> str:
        return views.mil_std_html(self)

    def to_json(self) -> dict[str, Any]:
        """JSON values in m/s; speeds and indices as lists."""
        found = {f.name: getattr(self, f.name) for f in attrs.fields(MilStd662F)}
        return {
            "method": "mil-std-662f",
            **{k: list(v) if isinstance(v, tuple) else v for k, v in found.items()},
            "rounds": self.rounds,
        }


def _rounds(weight: np.ndarray) -> np.ndarray:
    """How many rounds each shot stands for: its weight, which must be a whole number."""
    if not np.all(weight == np.round(weight)):
        raise ParameterError(
            "weight",
            "MIL-STD-662F averages rounds: weights must be whole numbers (how many shots "
            "a row stands for)",
        )
    return weight.astype(np.int64)


def mil_std_662f(
    speed: np.ndarray | Shots,
    perforated: np.ndarray | None = None,
    weight: np.ndarray | None = None,
    *,
    spread_m_s: float = DEFAULT_SPREAD,
    count: int | None = None,
    label: str = SHOTS,
) -> MilStd662F:
    """The MIL-STD-662F V50 of go/no-go shots: ``speed`` [m/s], ``perforated`` (bool;
    a non-perforation is a partial penetration) and ``weight`` (whole numbers: a row of
    weight 2 is two rounds at that speed; default 1) per shot; or ``speed`` is
    :class:`~plateimpact.Shots` alone, at one obliquity (``used`` then indexes them).

    ``count`` (2, 3 or 5) partial and as many complete penetrations are averaged; None
    takes the most that lie within ``spread_m_s`` [m/s] (default 38.1 m/s, 125 ft/s).
    Raises :class:`~plateimpact.base.errors.V50Error` (one line naming the shots ``label``)
    when the shots do not meet the standard's conditions.
    """
    v, y, w, label = go_no_go(speed, perforated, weight, label)
    low, high = SPREAD_RANGE
    if not low <= spread_m_s <= high:  # NaN fails too
        raise ParameterError(
            "spread", f"spread must be in [{low:g}, {high:g}] m/s, got {spread_m_s!r}"
        )
    if count is not None and count not in COUNTS:
        raise ParameterError(
            "count", f"count must be one of {', '.join(map(str, COUNTS))}, got {count!r}"
        )
    index = np.repeat(np.arange(v.size), _rounds(w))  # one entry per round
    partial = index[~y[index]][np.argsort(-v[index[~y[index]]], kind="stable")]
    complete = index[y[index]][np.argsort(v[index[y[index]]], kind="stable")]
    available = min(partial.size, complete.size)
    tried = COUNTS[::-1] if count is None else (count,)
    spans = {}
    for n in tried:
        if n > available:
            continue
        chosen = np.concatenate([partial[:n], complete[:n]])
        spans[n] = float(np.ptp(v[chosen]))
        if spans[n] <= spread_m_s:
            return MilStd662F(
                v50_m_s=float(np.mean(v[chosen])),
                count=n,
                spread_m_s=spans[n],
                spread_allowed_m_s=float(spread_m_s),
                partial_speeds_m_s=tuple(float(x) for x in v[partial[:n]]),
                complete_speeds_m_s=tuple(float(x) for x in v[complete[:n]]),
                used=tuple(int(i) for i in chosen),
                shots=int(index.size),
            )
    least = min(tried)
    if least > available:
        raise V50Error(
            f"{label}: MIL-STD-662F needs at least {least} partial and {least} complete "
            f"penetrations; the shots have {partial.size} and {complete.size}"
        )
    found = "; ".join(
        f"the {n} highest partial and {n} lowest complete penetrations span {span:.4g} m/s"
        for n, span in spans.items()
    )
    nearest = sorted((float(v[partial[0]]), float(v[complete[0]])))
    raise V50Error(
        f"{label}: MIL-STD-662F: {found}, more than the {spread_m_s:.4g} m/s allowed "
        f"(--spread); fire more shots between {nearest[0]:.6g} and {nearest[1]:.6g} m/s"
    )
