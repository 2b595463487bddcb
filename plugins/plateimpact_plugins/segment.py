"""The report's own integrator: constant-speed, constant-curvature segments (eqs 25–30)."""

from __future__ import annotations

from typing import ClassVar, final

import attrs
import numpy as np

from plateimpact import (
    KINEMATIC_STATE,
    LATERAL,
    MAX_SECONDS,
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
    # 1e-5, the finest step tested: 500 m/s at 30 deg on 2024-T3/3.18 would need 54,000
    # steps (40 s) there, and max_steps ends it; finer steps only add rounding to a
    # first-order method.
    range=Range(1e-5, 0.1),
    default=1e-3,
    flag="--step",
)


def arc(y: np.ndarray, rates: np.ndarray, dt: np.ndarray | float) -> np.ndarray:
    """The state after a time dt [s] on the segment from y with the rates at its start:
    the speed is V + dV/dt·dt (eq 25), the direction has turned by dθ/dt·dt (eqs 26–28),
    and the sphere has moved along the circular arc of that turn at the new speed (the
    chord of eqs 29–30); the failure state moves at its start rate."""
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


class Segments(DenseOutput):
    """A run of k segments as one dense output: σ in [j/k, (j+1)/k] lies on segment j."""

    __slots__ = ("dt", "rates", "starts")

    def __init__(self, starts: np.ndarray, rates: np.ndarray, dt: np.ndarray) -> None:
        self.starts, self.rates, self.dt = starts, rates, dt  # (k, d, n), (k, d, n), (n,)

    def __call__(self, sigma: float | np.ndarray) -> np.ndarray:
        k = self.starts.shape[0]
        if np.ndim(sigma) == 0 and float(sigma) * k in range(1, k):  # a segment's end
            return self.starts[int(float(sigma) * k)].copy()
        position = np.broadcast_to(np.asarray(sigma, dtype=float) * k, self.dt.shape)
        j = np.minimum(np.floor(position).astype(int), k - 1)
        scene = np.arange(self.dt.size)
        start, rate = self.starts[j, :, scene].T, self.rates[j, :, scene].T
        return arc(start, rate, self.dt * (position - j))

    def take(self, index: np.ndarray) -> Segments:
        return Segments(self.starts[:, :, index], self.rates[:, :, index], self.dt[index])


@final
@attrs.frozen
class Segment(Integrator):
    """NWC TP 5844's trajectory of segments with constant speed and curvature.

    Each segment lasts dt = ``step`` × Rs/Vs [s]. The force is evaluated at the start of
    the segment (step 1 of the report's procedure); the new speed is V' = V − F_D dt/m
    (eq 25) and the path turns by dθ = F_L dt/(m V) (eqs 26–28); the sphere then moves
    along the circular arc of that turn at the new speed V' ("from the new values for
    speed and curvature", step 4), which gives eqs 29–30 to first order. The method is
    first order in dt. The driver locates events on the arcs, so a segment that crosses
    P*, the rest speed or the end of contact ends there.

    The driver sees ``SEGMENTS`` segments as one step, sampled at every segment's end:
    the same segments, events and trajectory, with the driver's bookkeeping spread over
    them (segments computed past an event are discarded); ``max_steps`` counts such steps:
    a contact of C Rs/Vs takes C / (8 ``step``) of them, so the default 20,000 covers 160
    Rs/Vs at the default step (the longest of the presets' maps, 0-84 deg and 50-2000 m/s,
    is 145) and 16 Rs/Vs at 1e-4 (docs/robustness.md, "work bounds").
    """

    name = "segment"
    version = "2"
    #: Segments per driver step; the driver looks for events at each one's end.
    SEGMENTS: ClassVar[int] = 8
    event_samples = SEGMENTS + 1

    step: float = STEP.field()
    max_steps: int = MAX_STEPS.field()
    max_seconds: float | None = MAX_SECONDS.field()

    def initial_step(self, dynamics: Dynamics) -> np.ndarray:
        return self.SEGMENTS * self.step * dynamics.time_scale

    def advance(
        self, dynamics: Dynamics, t: np.ndarray, y: np.ndarray, h: np.ndarray, state: StepperState
    ) -> Step:
        dt = h / self.SEGMENTS
        starts = np.empty((self.SEGMENTS, *y.shape))
        rates = np.empty_like(starts)
        current = y
        for j in range(self.SEGMENTS):
            starts[j] = current
            # A segment longer than the time to stop (a stiff scene at a coarse step)
            # ends past rest, V <= V_rest: the driver keeps nothing after that event, and
            # a force evaluated there (V² of a speed far below zero, lift/(m V) of one
            # near it) would overflow. Such scenes coast on unchanged for the rest of the
            # step instead.
            stopped = dynamics.at_rest(current)
            if stopped.any():
                rates[j] = dynamics.rates(np.where(stopped, y, current))
                rates[j][:, stopped] = 0.0
            else:
                rates[j] = dynamics.rates(current)
            current = arc(current, rates[j], dt)
        return Step(current, h, None, Segments(starts, rates, dt), state)
