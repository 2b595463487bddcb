"""ImpactModel: the resolved model slots, and the force and event rules all integrators share."""

from __future__ import annotations

from collections.abc import Iterator
from typing import Any, ClassVar

import attrs
import numpy as np

from ..base.errors import PluginError
from ..base.parameters import Parameter, Range
from . import elementary
from .batch import SceneBatch
from .binding import BoundBatch, bind_scenes, check_declarations
from .events import (
    AT_REST,
    CONTACT_LOST,
    EVENTS,
    FAILURE_EVENTS,
    ONSET,
    PERFORATED,
    TURNED_BACK,
)
from .failure import Contact, FailureModel
from .geometry import branch_margins, contact_lost_margin
from .plugin import Plugin
from .resistance import BoundResistance, ResistanceLaw, contact_force

# At 1e-6 Vs a sphere has 1e-12 of its energy left; below, the rule would only chase
# dθ/dt = lift/(m V), which grows without bound as V falls.
REST_SPEED_FRACTION = Parameter(
    "rest_speed_fraction",
    "a sphere is at rest when its speed falls to this fraction of its impact speed",
    range=Range(1e-6, 1.0, high_open=True),
    default=1e-2,
)

#: Rows of the state vector y used by ODE integrators: P [m], Y [m], θ [rad], V [m/s],
#: then the failure model's state variables.
PENETRATION, LATERAL, OBLIQUITY, SPEED = range(4)
KINEMATIC_STATE = 4


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
    #: The rows of the failure events the failure model declares (set from its ``events``).
    _failure_rows: frozenset[int] = attrs.field(init=False, eq=False, repr=False)

    #: Obliquity is held here once reached (docs/model.md §4, "θ = π"): straight back out [rad].
    MAX_OBLIQUITY: ClassVar[float] = np.pi
    #: θ = π is a stable equilibrium that θ approaches exponentially, ever faster as V
    #: falls, and never reaches: it counts as reached this close [rad] (docs/model.md,
    #: "θ = π").
    TURN_BACK_TOLERANCE: ClassVar[float] = 1e-8

    def __attrs_post_init__(self) -> None:
        check_declarations(dict(self.plugins()))
        foreign = [e.name for e in self.failure.events if e not in FAILURE_EVENTS]
        if foreign:
            raise PluginError(
                f"failure {self.failure.name!r} declares event {foreign[0]!r}; a failure "
                f"model adds only {', '.join(e.name for e in FAILURE_EVENTS)}"
            )
        rows = frozenset(EVENTS.index(e) for e in self.failure.events)
        object.__setattr__(self, "_failure_rows", rows)

    def plugins(self) -> Iterator[tuple[str, Plugin]]:
        """(slot, plug-in) for each slot that sees the batch."""
        yield "resistance", self.resistance
        yield "failure", self.failure

    def plate_constants(self) -> dict[str, Parameter]:
        """Every plate constant the model reads, by name."""
        return {p.name: p for _, plugin in self.plugins() for p in plugin.plate_constants}

    def bind(self, batch: SceneBatch) -> BoundBatch:
        """The batch with every per-scene constant the step loop needs
        (``plateimpact.model.binding.bind_scenes``), computed once."""
        plugins = list(self.plugins())
        return bind_scenes(plugins, self.failure.onset_penetration, self.rest_speed_fraction, batch)

    def new_failure_state(self, size: int) -> np.ndarray:
        """Failure-state array for ``size`` scenes, shape (len(state_names), size): zero
        until :meth:`start_failure` sets it (the driver integrates those zeros unchanged,
        since the rates of an intact scene's failure state are zero)."""
        return np.zeros((len(self.failure.state_names), size))

    def _contact(
        self,
        index: np.ndarray | None,
        penetration: np.ndarray,
        obliquity: np.ndarray,
        speed: np.ndarray,
        failure_state: np.ndarray,
        batch: BoundBatch,
        obliquity_rate: np.ndarray | None = None,
    ) -> Contact:
        """The :class:`Contact` of the scenes at ``index`` (None: all of them)."""
        if index is None:
            law = BoundResistance(self.resistance, batch.resistance)
            return Contact(
                penetration, obliquity, speed, failure_state, batch.failure, law, obliquity_rate
            )
        law = BoundResistance(self.resistance, batch.resistance, index)
        return Contact(
            penetration[index],
            obliquity[index],
            speed[index],
            failure_state[:, index],
            batch.failure.take(index),
            law,
            None if obliquity_rate is None else obliquity_rate[index],
        )

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
        θ < 0 is the mirror image of ``|θ|`` (a path that has swung across the plate normal,
        which an explicit step near normal incidence can overshoot): the same drag, the
        lift reversed. The plug-ins only ever see θ >= 0 (docs/model.md, "mirror").
        """
        side = np.where(obliquity < 0.0, -1.0, 1.0)
        obliquity = np.abs(obliquity)
        drag, lift = contact_force(self.resistance, penetration, obliquity, speed, batch.resistance)
        if failed.all():  # no subset to take: every scene has failed
            contact = self._contact(None, penetration, obliquity, speed, failure_state, batch)
            extra_drag, extra_lift = self.failure.force_change(contact)
            return drag + extra_drag, side * (lift + extra_lift)
        if failed.any():
            index = np.flatnonzero(failed)
            contact = self._contact(index, penetration, obliquity, speed, failure_state, batch)
            extra_drag, extra_lift = self.failure.force_change(contact)
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
            contact = self._contact(index, penetration, obliquity, speed, failure_state, batch)
            failure_state[:, index] = self.failure.initial_state(contact)

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
            contact = self._contact(
                index, penetration, obliquity, speed, failure_state, batch, obliquity_rate
            )
            rates[:, index] = self.failure.state_rates(contact)
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
        # the geometry's sine and cosine (its own functions: the compiled path takes
        # them from the contact surface it has just evaluated, the same numbers)
        dy[PENETRATION] = spd * elementary.cos(obl)
        dy[LATERAL] = spd * elementary.sin(obl)
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
        """Event functions, shape (len(EVENTS), n), one row per declared event
        (:data:`~plateimpact.model.events.EVENTS`): the one definition of the outcome rules.

        Each crosses zero upward at its event and is −inf where the event cannot happen:
        failure onset (P − P*, intact plates), contact lost (θ − π/2 − α1), perforation
        (the failure model's margin, failed plates, while θ < π/2), rest (V_rest − V),
        turned back (θ − π + TURN_BACK_TOLERANCE, not yet held). A failure event the
        failure model does not declare is −inf throughout. Where two are reached at one
        point, the lower row wins: perforation over ricochet over embedment. ``kinds``:
        compute only these rows (the others are NaN), as root finding needs.
        """
        pen, obl = y[PENETRATION], np.abs(y[OBLIQUITY])  # θ < 0: the mirror image
        core = batch.core
        wanted = range(len(EVENTS)) if kinds is None else kinds
        shape = (len(EVENTS), pen.size)
        # Every row is written when all are wanted; NaN marks the rows not computed.
        margins = np.empty(shape) if kinds is None else np.full(shape, np.nan)
        added = self._failure_rows
        if ONSET in wanted:
            margins[ONSET] = (
                np.where(failed, -np.inf, pen - core.onset_penetration)
                if ONSET in added
                else -np.inf
            )
        if CONTACT_LOST in wanted:
            margins[CONTACT_LOST] = contact_lost_margin(pen, obl, core.radius)
        if PERFORATED in wanted:
            margins[PERFORATED] = (
                self._inward_perforation_margin(y, obl, failed, batch)
                if PERFORATED in added
                else -np.inf
            )
        if AT_REST in wanted:
            margins[AT_REST] = self.rest_margin(y[SPEED], batch)
        if TURNED_BACK in wanted:
            margins[TURNED_BACK] = np.where(
                held, -np.inf, obl - (self.MAX_OBLIQUITY - self.TURN_BACK_TOLERANCE)
            )
        return margins

    @staticmethod
    def rest_margin(speed: np.ndarray, batch: BoundBatch) -> np.ndarray:
        """V_rest − V [m/s]: >= 0 where the sphere is at rest (the embedment rule)."""
        return batch.core.rest_speed - speed

    def branch_margins(self, y: np.ndarray, failed: np.ndarray, batch: BoundBatch) -> np.ndarray:
        """Margins that cross zero where the force changes formula, shape (rows, n): the
        contact geometry's branch surfaces
        (:func:`plateimpact.model.geometry.branch_margins`), then the failure model's rows
        (:meth:`FailureModel.branch_margins`), NaN for intact scenes.

        Not events: nothing changes there but the smoothness of the force. The adaptive
        step control steps onto such a surface rather than across it.
        """
        pen, obl = y[PENETRATION], np.abs(y[OBLIQUITY])  # θ < 0: the mirror image
        rows = branch_margins(pen, obl, batch.core.radius)
        if not failed.any():
            return rows
        index = None if failed.all() else np.flatnonzero(failed)
        contact = self._contact(index, pen, obl, y[SPEED], y[KINEMATIC_STATE:], batch)
        failure_rows = self.failure.branch_margins(contact)
        if index is None:
            return np.concatenate([rows, failure_rows])
        extra = np.full((failure_rows.shape[0], pen.size), np.nan)
        extra[:, index] = failure_rows
        return np.concatenate([rows, extra])

    def perforation_margin(
        self, y: np.ndarray, obliquity: np.ndarray, failed: np.ndarray, batch: BoundBatch
    ) -> np.ndarray:
        """>= 0 where perforation is complete [m]; −inf where the plate is intact.
        ``obliquity`` θ >= 0 [rad] (the mirror image of y's)."""
        if not failed.any():
            return np.full(obliquity.shape, -np.inf)
        index = None if failed.all() else np.flatnonzero(failed)
        pen, speed, state = y[PENETRATION], y[SPEED], y[KINEMATIC_STATE:]
        contact = self._contact(index, pen, obliquity, speed, state, batch)
        found = self.failure.perforation_margin(contact)
        if index is None:
            return np.asarray(found, dtype=float)
        margin = np.full(obliquity.shape, -np.inf)
        margin[index] = found
        return margin

    def _inward_perforation_margin(
        self, y: np.ndarray, obliquity: np.ndarray, failed: np.ndarray, batch: BoundBatch
    ) -> np.ndarray:
        """The perforation margin where it counts: only while the sphere moves inward
        (θ < 90°); −inf elsewhere and on intact plates."""
        margin = self.perforation_margin(y, obliquity, failed, batch)
        return np.where(obliquity < 0.5 * np.pi, margin, -np.inf)

    def describe(self) -> dict[str, object]:
        """Each slot's plug-in name, version and settings, and the rest rule, for output
        and archives (``SLOT``, ``SLOT_version``, ``SLOT_settings``)."""
        described: dict[str, object] = {}
        for slot, plugin in self.plugins():
            described.update(describe_plugin(slot, plugin))
        described["rest_speed_fraction"] = self.rest_speed_fraction
        return described


def describe_plugin(slot: str, plugin: Plugin) -> dict[str, object]:
    """``{SLOT: name, SLOT_version: version, SLOT_settings: settings}`` of one slot."""
    return {
        slot: plugin.name,
        f"{slot}_version": plugin.version,
        f"{slot}_settings": plugin.settings(),
    }
