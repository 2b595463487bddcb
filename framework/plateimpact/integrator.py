"""The Integrator interface: a stepper that the core driver runs.

The driver (:mod:`plateimpact.driver`) owns everything integrators share: binding the
batch, the events and their order, failure onset, the θ = π hold, rest, recording,
dropping finished scenes, step-size control. An integrator supplies only what is its
own: its first step, one step of the active scenes (with its error estimate, if it has
one) and a dense output on which the driver locates events.
"""

from __future__ import annotations

from abc import ABC, abstractmethod
from typing import ClassVar, NamedTuple

import numpy as np

from .dense import DenseOutput
from .dynamics import Dynamics
from .parameters import Parameter, Range
from .plugin import Plugin

#: Per-scene arrays a stepper carries from one accepted step to the next (last axis:
#: scenes). ``derivative`` (d, n), if present, is f(y) at the current state, which the
#: driver then uses instead of evaluating it again (branch prediction).
StepperState = dict[str, np.ndarray]

MAX_STEPS = Parameter(
    "max_steps",
    "give up (IntegrationError) when a scene has not finished after this many steps",
    kind=int,
    range=Range(1.0),
    default=200_000,
)
#: A scene's wall time is its share of the loop's: each step's time divided among the
#: scenes still running. 20 s leaves a single-scene command (under 1 s to start, a few to
#: write its outputs) inside 30 s, and is far above what an ordinary scene needs (500 m/s
#: at 30° on 2024-T3/3.18: 0.05 s with dopri5 or solve_ivp, 4 s with segment at step 1e-4).
MAX_SECONDS = Parameter(
    "max_seconds",
    "give up (IntegrationError) when a scene has used this much wall time (each step's "
    "time shared among the scenes still running; inf: no limit)",
    "s",
    Range(0.0, low_open=True, allow_inf=True),
    default=20.0,
)
# 1e-13 is the tightest tolerance the project uses (the work-precision reference): a few
# hundred times the rounding of a double, below which steps shrink without gaining.
RTOL = Parameter(
    "rtol",
    "local error tolerance relative to each component's scale (Rs, 1 rad, Vs)",
    range=Range(1e-13, 1e-2),
    default=1e-8,
    flag="--rtol",
)


class StepControl(NamedTuple):
    """How the driver controls an adaptive integrator's steps.

    ``rtol``: local error per step relative to each component's scale; ``error_order``:
    the step follows err^(−1/error_order); ``branch_landing``: step onto the surfaces
    where the force stops being smooth instead of across them (docs/integrators.md).
    """

    rtol: float
    error_order: int
    branch_landing: bool = True


class Step(NamedTuple):
    """One step of every active scene.

    ``y`` (d, n): states at t + h; ``h`` (n,): the step taken [s]; ``error`` (d, n): the
    local error estimate, or None (no error control: fixed steps, or a solver that
    controls its own); ``dense``: the states inside the step; ``state``: what to carry
    to the next step where this one is accepted.
    """

    y: np.ndarray
    h: np.ndarray
    error: np.ndarray | None
    dense: DenseOutput
    state: StepperState


class Integrator(Plugin, ABC):
    """Advances a batch of scenes one step at a time; the driver does the rest.

    The state of a scene is its penetration P [m], lateral displacement Y [m], obliquity
    θ [rad] and speed V [m/s], then the failure model's state; ``dynamics.rates(y)`` is
    dy/dt (eqs 25–30). Steps work on whole arrays: no Python loop over scenes.

    Subclass, set ``name``, declare settings as attrs fields, and implement
    :meth:`initial_step` and :meth:`advance`; override :meth:`start`, :meth:`restart` and
    :meth:`step_control` as needed.
    """

    #: Give up after this many steps, or when a scene has used this much wall time [s]
    #: (settings in the built-ins: :data:`MAX_STEPS`, :data:`MAX_SECONDS`).
    max_steps: int = 200_000
    max_seconds: float = 20.0
    #: Equally spaced samples per step, ends included, at which the driver looks for
    #: events and records the trajectory: more for long steps, 2 for very short ones.
    event_samples: ClassVar[int] = 5

    def step_control(self) -> StepControl | None:
        """Error control for this run; None: every finite step is accepted and ``h``
        stays at its initial value (default)."""
        return None

    @abstractmethod
    def initial_step(self, dynamics: Dynamics) -> np.ndarray:
        """The first step of every scene [s] (``dynamics.time_scale`` is Rs/Vs)."""

    def start(self, dynamics: Dynamics, t: np.ndarray, y: np.ndarray) -> StepperState:
        """What the stepper carries between steps, at the initial state (default none)."""
        return {}

    @abstractmethod
    def advance(
        self, dynamics: Dynamics, t: np.ndarray, y: np.ndarray, h: np.ndarray, state: StepperState
    ) -> Step:
        """One step of length ``h`` [s] of every scene from (t, y)."""

    def restart(
        self,
        dynamics: Dynamics,
        t: np.ndarray,
        y: np.ndarray,
        state: StepperState,
        index: np.ndarray,
    ) -> StepperState:
        """The carried state after the driver changed the scenes at ``index``: failure
        onset, the 180° hold (new right-hand side, new y). Default: ``start`` there."""
        fresh = self.start(dynamics.take(index), t[index], y[:, index])
        for key, values in fresh.items():
            state[key][..., index] = values
        return state
