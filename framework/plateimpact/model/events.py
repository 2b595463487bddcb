"""The events of an impact, declared once: their order, what each one means, and which
a failure model adds.

An event is where one of the model's event margins (:meth:`ImpactModel.event_margins`)
crosses zero upward. The driver locates them on each step's dense output; its rows, the
count of rows and every table keyed by event kind are derived from :data:`EVENTS`, so an
event is added here and nowhere else.
"""

from __future__ import annotations

import attrs

from .results import Outcome


@attrs.frozen
class Event:
    """One kind of event.

    ``name`` says what happens (archives and messages use it); ``outcome`` is how the
    impact ends there (None: it goes on); ``restarts``: the right-hand side changes
    there (the plate fails, θ is held at 180°), so a stepper that carries state from step
    to step starts afresh; ``description`` says where the margin crosses zero.
    """

    name: str
    outcome: Outcome | None
    restarts: bool
    description: str


FAILURE_ONSET = Event(
    "failure onset", None, True, "P reaches the failure model's onset penetration (P*)"
)
LOSS_OF_CONTACT = Event(
    "contact lost", Outcome.RICOCHET, False, "θ − π/2 − α1 = 0: the sphere leaves the surface"
)
PERFORATION = Event(
    "perforated",
    Outcome.PERFORATION,
    False,
    "the failure model's perforation margin, while the sphere moves inward (θ < 90°)",
)
REST = Event("at rest", Outcome.EMBEDMENT, False, "V falls to the rest speed")
TURN_BACK = Event("turned back", None, True, "θ reaches 180°, where it is held")

#: Every event, in the order that breaks ties: where two are reached at one point, the
#: earlier wins (perforation over ricochet over embedment).
EVENTS: tuple[Event, ...] = (FAILURE_ONSET, LOSS_OF_CONTACT, PERFORATION, REST, TURN_BACK)
#: The events a failure model may add (:attr:`FailureModel.events`).
FAILURE_EVENTS: tuple[Event, ...] = (FAILURE_ONSET, PERFORATION)

#: Row of each event in the margins: the driver's ``event_kind``.
ONSET = EVENTS.index(FAILURE_ONSET)
CONTACT_LOST = EVENTS.index(LOSS_OF_CONTACT)
PERFORATED = EVENTS.index(PERFORATION)
AT_REST = EVENTS.index(REST)
TURNED_BACK = EVENTS.index(TURN_BACK)
#: Each event's name, by row.
EVENT_NAMES = tuple(event.name for event in EVENTS)
#: The rows that end an impact, and the outcome each one means.
EVENT_OUTCOMES = {row: e.outcome for row, e in enumerate(EVENTS) if e.outcome is not None}
#: The rows where the right-hand side changes (steppers restart there).
RESTARTING = tuple(row for row, event in enumerate(EVENTS) if event.restarts)
