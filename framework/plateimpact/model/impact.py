"""ImpactModel: the resolved model slots, and the force and event rules all integrators share."""

from __future__ import annotations

from collections.abc import Iterator
from typing import Any, ClassVar

import attrs
import numpy as np

from ..base.errors import ParameterError, PluginError
from ..base.parameters import Parameter, Range
from .batch import CORE_COLUMNS, SceneBatch
from .binding import BoundBatch
from .failure import FailureModel
from .geometry import branch_margins, contact_lost_margin
from .plugin import Plugin
from .resistance import BoundResistance, ResistanceLaw, contact_force
from .results import Outcome

# At 1e-6 Vs a sphere has 1e-12 of its energy left; below, the rule would only chase
# dθ/dt = lift/(m V), which grows without bound as V falls.
REST_SPEED_FRACTION = Parameter(
    "rest_speed_fraction",
    "a sphere is at rest when its speed falls to this fraction of its impact speed",
    range=Range(1e-6, 1.0, high_open=True),
    default=1e-2,
)
ONSET_PENETRATION = Parameter(
    "onset_penetration",
    "penetration at which the plate fails (the failure model's; inf: never)",
    "m",
    Range(0.0, low_open=True, allow_inf=True),
    "mm",
    1e-3,
)

#: Rows of the state vector y used by ODE integrators: P [m], Y [m], θ [rad], V [m/s],
#: then the failure model's state variables.
PENETRATION, LATERAL, OBLIQUITY, SPEED = range(4)
KINEMATIC_STATE = 4

#: Rows of :meth:`ImpactModel.event_margins`. Each margin crosses zero upward at its event.
ONSET, CONTACT_LOST, PERFORATED, AT_REST, TURNED_BACK = range(5)
EVENT_NAMES = ("failure onset", "contact lost", "perforated", "at rest", "turned back")
#: The events that end an impact, and the outcome each one means.
EVENT_OUTCOMES = {
    CONTACT_LOST: Outcome.RICOCHET,
    PERFORATED: Outcome.PERFORATION,
    AT_REST: Outcome.EMBEDMENT,
}


def _plugin_of(kind: type) -> Any:
    """An attrs validator: an instance of the (abstract) plug-in interface ``kind``."""

    def check(instance: object, attribute: attrs.Attribute, value: object) -> None:
        if not isinstance(value, kind):
            raise PluginError(f"{attribute.name} must be a {kind.__name__}, got {value!r}")

    return check


@attrs.frozen
class ImpactModel:
    """A resistance law and a failure model, resolved once, used on whole batches.

    Parameters
    ----------
    resistance : ResistanceLaw
    failure : FailureModel
    rest_speed_fraction : float
        The embedment rule (docs/model.md, "rest"): a sphere is at rest when its speed
        falls to this fraction of its impact speed; its exit obliquity is its direction
        then. In (0, 1); default 0.01.

    The methods take arrays with one entry per scene: ``penetration`` P [m],
    ``obliquity`` θ [rad], ``speed`` V [m/s], ``obliquity_rate`` dθ/dt [rad/s]; ``y``
    the state rows :data:`PENETRATION` ... in those units.
    """

    resistance: ResistanceLaw = attrs.field(validator=_plugin_of(ResistanceLaw))
    failure: FailureModel = attrs.field(validator=_plugin_of(FailureModel))
    rest_speed_fraction: float = REST_SPEED_FRACTION.field()

    #: Obliquity is held here once reached (docs/model.md §4, "θ = π"): straight back out [rad].
    MAX_OBLIQUITY: ClassVar[float] = np.pi
    #: θ = π is a stable equilibrium that θ approaches exponentially, ever faster as V
    #: falls, and never reaches: it counts as reached this close [rad] (docs/model.md,
    #: "θ = π").
    TURN_BACK_TOLERANCE: ClassVar[float] = 1e-8

    def __attrs_post_init__(self) -> None:
        check_declarations(dict(self.plugins()))

    def plugins(self) -> Iterator[tuple[str, Plugin]]:
        """(slot, plug-in) for each slot that sees the batch."""
        yield "resistance", self.resistance
        yield "failure", self.failure

    def plate_constants(self) -> dict[str, Parameter]:
        """Every plate constant the model reads, by name."""
        return {p.name: p for _, plugin in self.plugins() for p in plugin.plate_constants}

    # -- binding ---------------------------------------------------------------------

    def bind(self, batch: SceneBatch) -> BoundBatch:
        """The batch with every per-scene constant the step loop needs, computed once and
        namespaced: the plate constants each plug-in declared (checked against their
        ranges, or their defaults where the plate has none), the columns each prepared,
        ``onset_penetration`` [m] and ``rest_speed`` [m/s]."""
        n = batch.size
        given = batch.columns
        columns = {name: given[name] for name in CORE_COLUMNS}
        keys: dict[str, dict[str, str]] = {}
        for slot, plugin in self.plugins():
            visible = {name: name for name in CORE_COLUMNS}
            for declared in plugin.plate_constants:
                if declared.name not in columns:
                    columns[declared.name] = _constant_column(declared, given, n, slot, plugin)
                visible[declared.name] = declared.name
            view = SceneBatch.of({k: columns[v] for k, v in visible.items()}, n)
            prepared = plugin.prepare(view)  # type: ignore[attr-defined]
            for name, values in _checked_columns(slot, plugin, prepared, n).items():
                columns[f"{slot}.{name}"] = values
                visible[name] = f"{slot}.{name}"
            keys[slot] = visible
        failure_view = SceneBatch.of({k: columns[v] for k, v in keys["failure"].items()}, n)
        onset = np.broadcast_to(
            np.asarray(self.failure.onset_penetration(failure_view), dtype=float), (n,)
        )
        ONSET_PENETRATION.check(onset)
        columns["onset_penetration"] = np.ascontiguousarray(onset)
        columns["rest_speed"] = self.rest_speed_fraction * given["impact_speed"]
        keys["core"] = {name: name for name in (*CORE_COLUMNS, "onset_penetration", "rest_speed")}
        return BoundBatch(columns, keys, n)

    def new_failure_state(self, size: int) -> np.ndarray:
        """Failure-state array for ``size`` scenes, shape (len(state_names), size).

        NaN until :meth:`start_failure` sets it: before failure it means nothing.
        """
        return np.full((len(self.failure.state_names), size), np.nan)

    # -- forces and rates --------------------------------------------------------------

    def forces(
        self,
        penetration: np.ndarray,
        obliquity: np.ndarray,
        speed: np.ndarray,
        failed: np.ndarray,
        failure_state: np.ndarray,
        batch: BoundBatch,
    ) -> tuple[np.ndarray, np.ndarray]:
        """Net drag and lift [N] on every scene (eqs 1, 15, 21–24).

        The failure model is consulted only for the scenes whose plate has failed.
        θ < 0 is the mirror image of |θ| (a path that has swung across the plate normal,
        which an explicit step near normal incidence can overshoot): the same drag, the
        lift reversed. The plug-ins only ever see θ >= 0 (docs/model.md, "mirror").
        """
        side = np.where(obliquity < 0.0, -1.0, 1.0)
        obliquity = np.abs(obliquity)
        law = batch.resistance
        drag, lift = contact_force(self.resistance, penetration, obliquity, speed, law)
        if failed.all():  # no subset to take: every scene has failed
            extra_drag, extra_lift = self.failure.force_change(
                penetration,
                obliquity,
                speed,
                failure_state,
                batch.failure,
                BoundResistance(self.resistance, law),
            )
            return drag + extra_drag, side * (lift + extra_lift)
        if failed.any():
            index = np.flatnonzero(failed)
            extra_drag, extra_lift = self.failure.force_change(
                penetration[index],
                obliquity[index],
                speed[index],
                failure_state[:, index],
                batch.failure.take(index),
                BoundResistance(self.resistance, law.take(index)),
            )
            drag[index] += extra_drag
            lift[index] += extra_lift
        return drag, side * lift

    def start_failure(
        self,
        onset: np.ndarray,
        penetration: np.ndarray,
        obliquity: np.ndarray,
        speed: np.ndarray,
        failure_state: np.ndarray,
        batch: BoundBatch,
    ) -> None:
        """Set the failure state of the scenes in the boolean mask ``onset`` (in place)."""
        if failure_state.shape[0] and onset.any():
            index = np.flatnonzero(onset)
            failure_state[:, index] = self.failure.initial_state(
                penetration[index], obliquity[index], speed[index], batch.failure.take(index)
            )

    def failure_state_rates(
        self,
        penetration: np.ndarray,
        obliquity: np.ndarray,
        speed: np.ndarray,
        obliquity_rate: np.ndarray,
        failed: np.ndarray,
        failure_state: np.ndarray,
        batch: BoundBatch,
    ) -> np.ndarray:
        """d(failure state)/dt; zero for intact scenes and stateless models."""
        rates = np.zeros_like(failure_state)
        if failure_state.shape[0] and failed.any():
            index = np.flatnonzero(failed)
            rates[:, index] = self.failure.state_rates(
                penetration[index],
                obliquity[index],
                speed[index],
                obliquity_rate[index],
                failure_state[:, index],
                batch.failure.take(index),
            )
        return rates

    def rates(
        self, y: np.ndarray, failed: np.ndarray, held: np.ndarray, batch: BoundBatch
    ) -> np.ndarray:
        """dy/dt for the state rows of :data:`PENETRATION` ... (eqs 25–30 in time form):
        dP/dt = V cos θ, dY/dt = V sin θ, dθ/dt = lift/(m V) (0 where ``held`` at 180°),
        dV/dt = −drag/m, then the failure state's rates."""
        pen, obl, spd = y[PENETRATION], y[OBLIQUITY], y[SPEED]
        failure_state = y[KINEMATIC_STATE:]
        drag, lift = self.forces(pen, obl, spd, failed, failure_state, batch)
        mass = batch.core.mass
        obliquity_rate = np.where(held, 0.0, lift / (mass * spd))
        dy = np.empty_like(y)
        dy[PENETRATION] = spd * np.cos(obl)
        dy[LATERAL] = spd * np.sin(obl)
        dy[OBLIQUITY] = obliquity_rate
        dy[SPEED] = -drag / mass
        # The failure model sees the mirror image for θ < 0: |θ| and d|θ|/dt.
        side = np.where(obl < 0.0, -1.0, 1.0)
        dy[KINEMATIC_STATE:] = self.failure_state_rates(
            pen, side * obl, spd, side * obliquity_rate, failed, failure_state, batch
        )
        return dy

    # -- events ------------------------------------------------------------------------

    def event_margins(
        self,
        y: np.ndarray,
        failed: np.ndarray,
        held: np.ndarray,
        batch: BoundBatch,
        kinds: frozenset[int] | None = None,
    ) -> np.ndarray:
        """Event functions, shape (5, n), rows :data:`ONSET` ... :data:`TURNED_BACK`: the
        one definition of the outcome rules.

        Each crosses zero upward at its event and is −inf where the event cannot happen:
        failure onset (P − P*, intact plates), contact lost (θ − π/2 − α1), perforation
        (the failure model's margin, failed plates, while θ < π/2), rest (V_rest − V),
        turned back (θ − π + TURN_BACK_TOLERANCE, not yet held). Where two are reached at
        one point, the lower row wins: perforation over ricochet over embedment.
        ``kinds``: compute only these rows (the others are NaN), as root finding needs.
        """
        pen, obl = y[PENETRATION], np.abs(y[OBLIQUITY])  # θ < 0: the mirror image
        core = batch.core
        every = kinds is None
        margins = np.full((5, pen.size), np.nan) if not every else np.empty((5, pen.size))
        if every or ONSET in kinds:  # type: ignore[operator]
            margins[ONSET] = np.where(failed, -np.inf, pen - core.onset_penetration)
        if every or CONTACT_LOST in kinds:  # type: ignore[operator]
            margins[CONTACT_LOST] = contact_lost_margin(pen, obl, core.radius)
        if every or PERFORATED in kinds:  # type: ignore[operator]
            margins[PERFORATED] = self._inward_perforation_margin(pen, obl, failed, batch)
        if every or AT_REST in kinds:  # type: ignore[operator]
            margins[AT_REST] = core.rest_speed - y[SPEED]
        if every or TURNED_BACK in kinds:  # type: ignore[operator]
            margins[TURNED_BACK] = np.where(
                held, -np.inf, obl - (self.MAX_OBLIQUITY - self.TURN_BACK_TOLERANCE)
            )
        return margins

    def branch_margins(self, y: np.ndarray, failed: np.ndarray, batch: BoundBatch) -> np.ndarray:
        """Margins that cross zero where the force changes formula, shape (rows, n): the
        contact geometry's branch surfaces (:func:`geometry.branch_margins`), then the
        failure model's rows (:meth:`FailureModel.branch_margins`), NaN for intact scenes.

        Not events: nothing changes there but the smoothness of the force. The adaptive
        step control steps onto such a surface rather than across it.
        """
        pen, obl = y[PENETRATION], np.abs(y[OBLIQUITY])  # θ < 0: the mirror image
        rows = branch_margins(pen, obl, batch.core.radius)
        if not failed.any():
            return rows
        index = np.flatnonzero(failed)
        failure_rows = self.failure.branch_margins(
            pen[index], obl[index], y[KINEMATIC_STATE:, index], batch.failure.take(index)
        )
        extra = np.full((failure_rows.shape[0], pen.size), np.nan)
        extra[:, index] = failure_rows
        return np.concatenate([rows, extra])

    def perforation_margin(
        self, penetration: np.ndarray, obliquity: np.ndarray, failed: np.ndarray, batch: BoundBatch
    ) -> np.ndarray:
        """>= 0 where perforation is complete [m]; −inf where the plate is intact."""
        margin = np.full(penetration.shape, -np.inf)
        if failed.any():
            index = np.flatnonzero(failed)
            margin[index] = self.failure.perforation_margin(
                penetration[index], np.abs(obliquity[index]), batch.failure.take(index)
            )
        return margin

    def _inward_perforation_margin(
        self, penetration: np.ndarray, obliquity: np.ndarray, failed: np.ndarray, batch: BoundBatch
    ) -> np.ndarray:
        """The perforation margin where it counts: only while the sphere moves inward
        (θ < 90°); −inf elsewhere and on intact plates."""
        margin = self.perforation_margin(penetration, obliquity, failed, batch)
        return np.where(obliquity < 0.5 * np.pi, margin, -np.inf)

    def describe(self) -> dict[str, object]:
        """Plug-in names, versions and settings, for output and archives."""
        return {
            "resistance": self.resistance.name,
            "resistance_version": self.resistance.version,
            "resistance_settings": self.resistance.settings(),
            "failure": self.failure.name,
            "failure_version": self.failure.version,
            "failure_settings": self.failure.settings(),
            "rest_speed_fraction": self.rest_speed_fraction,
        }


def check_declarations(plugins: dict[str, Any]) -> None:
    """Refuse, with one line, plug-ins whose declarations clash: one plate constant
    declared two ways, or a prepared column that shadows a core column or constant."""
    seen: dict[str, tuple[Parameter, str]] = {}
    for slot, plugin in plugins.items():
        label = f"{slot} {plugin.name!r}"
        for declared in plugin.plate_constants:
            if declared.name in CORE_COLUMNS:
                raise PluginError(
                    f"{label} declares plate constant {declared.name!r}, a core column"
                )
            if declared.name in seen and seen[declared.name][0] != declared:
                raise PluginError(
                    f"{seen[declared.name][1]} and {label} both claim plate constant "
                    f"{declared.name!r} with different declarations"
                )
            seen.setdefault(declared.name, (declared, label))
        shadowed = {c.name for c in plugin.columns} & (
            set(CORE_COLUMNS) | {p.name for p in plugin.plate_constants}
        )
        if shadowed:
            raise PluginError(f"{label} prepares column {sorted(shadowed)[0]!r}, a name it reads")


def _constant_column(
    declared: Parameter, given: dict[str, np.ndarray], n: int, slot: str, plugin: Plugin
) -> np.ndarray:
    """The plate constant a plug-in declared: the plate's, checked, or its default."""
    if declared.name in given:
        declared.check(given[declared.name])
        return given[declared.name]
    if declared.has_default:
        return np.full(n, float(declared.default))  # type: ignore[arg-type]
    raise ParameterError(
        declared.name,
        f"{declared.name} ({declared.description}) is needed by {slot} {plugin.name!r} and "
        f"has no default: give the plate one ({declared.describe_range()})",
    )


def _checked_columns(
    slot: str, plugin: Plugin, prepared: dict[str, Any], n: int
) -> dict[str, np.ndarray]:
    """The columns a plug-in prepared, exactly those it declared, one float per scene."""
    declared = [c.name for c in plugin.columns]
    if set(prepared) != set(declared):
        extra, missing = (
            sorted(set(prepared) - set(declared)),
            sorted(set(declared) - set(prepared)),
        )
        what = f"undeclared column {extra[0]!r}" if extra else f"no column {missing[0]!r}"
        raise PluginError(f"{slot} {plugin.name!r}: prepare() returned {what}")
    return {
        name: np.ascontiguousarray(np.broadcast_to(np.asarray(prepared[name], float), (n,)))
        for name in declared
    }
