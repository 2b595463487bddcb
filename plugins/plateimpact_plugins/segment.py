"""The report's own integrator: constant-speed, constant-curvature segments (eqs 25–30)."""

from __future__ import annotations

from typing import final

import attrs
import numpy as np

from plateimpact import (
    KINEMATIC_STATE,
    LATERAL,
    MAX_STEPS,
    OBLIQUITY,
    PENETRATION,
    SPEED,
    DenseOutput,
    Dynamics,
    Integrator,
    Parameter,
    Range,
    Step,
    StepperState,
)

STEP = Parameter(
    "step",
    "segment duration as a fraction of Rs/Vs, the time to travel one radius at impact "
    "speed (finest documented 1e-4)",
    range=Range(0.0, 0.1, low_open=True),
    default=1e-3,
    flag="--step",
)


class Arc(DenseOutput):
    """The segment from y with the rates at its start: after a time σ·dt the speed is
    V + dV/dt·σdt (eq 25), the direction has turned by dθ/dt·σdt (eqs 26–28), and the
    sphere has moved along the circular arc of that turn at the new speed (the chord of
    eqs 29–30); the failure state moves at its start rate."""

    __slots__ = ("dt", "rates", "y")

    def __init__(self, y: np.ndarray, rates: np.ndarray, dt: np.ndarray) -> None:
        self.y, self.rates, self.dt = y, rates, dt

    def __call__(self, sigma: float | np.ndarray) -> np.ndarray:
        y, rates, dt = self.y, self.rates, self.dt * sigma
        speed = y[SPEED] + rates[SPEED] * dt
        turn = rates[OBLIQUITY] * dt
        chord = speed * dt * np.sinc(turn / (2.0 * np.pi))  # arc of length V'dt, turning dθ
        heading = y[OBLIQUITY] + 0.5 * turn
        out = np.empty_like(y)
        out[PENETRATION] = y[PENETRATION] + chord * np.cos(heading)
        out[LATERAL] = y[LATERAL] + chord * np.sin(heading)
        out[OBLIQUITY] = y[OBLIQUITY] + turn
        out[SPEED] = speed
        out[KINEMATIC_STATE:] = y[KINEMATIC_STATE:] + rates[KINEMATIC_STATE:] * dt
        return out

    def take(self, index: np.ndarray) -> Arc:
        return Arc(self.y[:, index], self.rates[:, index], self.dt[index])


@final
@attrs.frozen
class Segment(Integrator):
    """NWC TP 5844's trajectory of segments with constant speed and curvature.

    Each segment lasts dt = ``step`` × Rs/Vs [s]. The force is evaluated at the start of
    the segment (step 1 of the report's procedure); the new speed is V' = V − F_D dt/m
    (eq 25) and the path turns by dθ = F_L dt/(m V) (eqs 26–28); the sphere then moves
    along the circular arc of that turn at the new speed V' ("from the new values for
    speed and curvature", step 4), which gives eqs 29–30 to first order. The method is
    first order in dt. The driver locates events on the arc, so a segment that crosses
    P*, the rest speed or the end of contact ends there.
    """

    name = "segment"
    version = "2"
    #: A segment is short: its ends are enough to see an event in it.
    event_samples = 2

    step: float = STEP.field()
    max_steps: int = attrs.evolve(MAX_STEPS, default=20_000_000).field()

    def initial_step(self, dynamics: Dynamics) -> np.ndarray:
        return self.step * dynamics.time_scale

    def advance(
        self, dynamics: Dynamics, t: np.ndarray, y: np.ndarray, h: np.ndarray, state: StepperState
    ) -> Step:
        arc = Arc(y, dynamics.rates(y), h)
        return Step(arc(1.0), h, None, arc, state)
