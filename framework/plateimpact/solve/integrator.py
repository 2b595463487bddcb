"""The Integrator interface: a stepper that the core driver runs.

The driver (:mod:`plateimpact.solve.driver`) owns everything integrators share: binding the
batch, the events and their order, failure onset, the θ = π hold, rest, recording,
dropping finished scenes, step-size control. An integrator supplies only what is its
own: its first step, one step of the active scenes (with its error estimate, if it has
one) and a dense output on which the driver locates events.
"""

from __future__ import annotations

from abc import ABC, abstractmethod
from typing import ClassVar, NamedTuple

import numpy as np

from ..base.parameters import Parameter, Range
from ..model.plugin import Plugin
from .dense import DenseOutput
from .dynamics import Dynamics

#: Per-scene arrays a stepper carries from one accepted step to the next, by names of the
#: stepper's own choosing (last axis: scenes). The driver selects, subsets and restarts
#: them but never reads a key: what it may use of them, a stepper says through methods
#: (:meth:`Integrator.known_rates`).
StepperState = dict[str, np.ndarray]

#: The work bound of every built-in integrator, counted (never timed), so that where a
#: scene ends never depends on the machine's speed or load. 20,000 steps is at least 1e4
#: Rs/Vs at dopri5's largest step (0.5 Rs/Vs; solve_ivp's longest_phase is the same 1e4):
#: 23 times what the report's figures, maps and limits need (at most 859 steps, dopri5 at
#: rtol 1e-8 to 1e-13), 1.7 times the longest scene of the property tests' domain (11,836:
#: a = 3e7 N/m², b = 30 kg/m³, 5 km/s, intact), and for the segment method contacts of
#: 160 Rs/Vs at its default step (the longest map scene: 145). A scene that needs more
#: ends after 15-25 s of one core (docs/robustness.md, "work bounds").
MAX_STEPS = Parameter(
    "max_steps",
    "give up (IntegrationError) when a scene has not finished after this many steps",
    kind=int,
    range=Range(1.0),
    default=20_000,
)
#: An opt-in safety net only, off by default: a wall-time limit would make a scene's end
#: depend on how fast and how busy the machine is. When set, it ends a run with an
#: IntegrationError naming it; it never changes a result. A scene's wall time is its
#: share of the loop's: each step's time divided among the scenes still running.
MAX_SECONDS = Parameter(
    "max_seconds",
    "give up (IntegrationError) when a scene has used this much wall time (each step's "
    "time shared among the scenes still running; default none: no limit, the step bound "
    "alone ends a run)",
    "s",
    Range(0.0, low_open=True, allow_inf=True),
    # None, not inf: JSON outputs and archives record it as null, which strict JSON
    # readers (jq, JavaScript) take; inf is accepted and means the same.
    default=None,
    optional=True,
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


class PairTableau(NamedTuple):
    """An explicit embedded Runge–Kutta pair with first-same-as-last stage and polynomial
    dense output, as data: ``C`` (s,), ``A`` (s, s), ``B`` (s,), the error weights ``E``
    (s + 1,: the last for the FSAL stage), the dense-output matrix ``P`` (s + 1, Q:
    coefficients of σ, σ², ...) and ``error_order`` (the step follows
    err^(−1/error_order)). What the compiled path integrates with."""

    C: np.ndarray
    A: np.ndarray
    B: np.ndarray
    E: np.ndarray
    P: np.ndarray
    error_order: int


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

    #: Give up after this many steps, or (opt-in: None by default, no limit) when a scene
    #: has used this much wall time [s] (settings in the built-ins: :data:`MAX_STEPS`,
    #: :data:`MAX_SECONDS`).
    max_steps: int = 20_000
    max_seconds: float | None = None
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

    def compiled_tableau(self) -> PairTableau | None:
        """The pair this integrator steps with, if it is an embedded Runge–Kutta pair with
        error control that the compiled path can run in its place, taking the same steps
        (:mod:`plateimpact.solve.compiled`); None (default): the numpy path only."""
        return None

    def known_rates(self, state: StepperState) -> np.ndarray | None:
        """dy/dt at the current state, shape (d, n), if the carried ``state`` holds it (a
        first-same-as-last pair's last stage), so that the driver need not evaluate it
        again (the branch prediction of adaptive steps); None (default): not known."""
        return None

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
