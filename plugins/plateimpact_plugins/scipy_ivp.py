"""scipy's ODE solvers as a stepper: the side-by-side reference."""

from __future__ import annotations

from typing import Any, final

import attrs
import numpy as np

from plateimpact import (
    MAX_SECONDS,
    MAX_STEPS,
    RTOL,
    DenseOutput,
    Dynamics,
    IntegrationError,
    Integrator,
    Parameter,
    Range,
    Step,
    StepperState,
)

METHODS = ("DOP853", "RK45", "RK23", "LSODA", "Radau", "BDF")

METHOD = Parameter(
    "method", "the scipy.integrate solver", kind=str, choices=METHODS, default="DOP853"
)
# Each solver is built with an end time (scipy's t_bound); a scene still unfinished there
# is an error, not an outcome. 1e4 Rs/Vs is ten times the longest ordinary scene (a
# grazing sphere sliding on a plate that barely resists), a second or so of work.
LONGEST_PHASE = Parameter(
    "longest_phase",
    "give up (IntegrationError) when a scene has spent this long, as a multiple of Rs/Vs, "
    "since contact or its last restart (failure onset, the 180 deg hold)",
    range=Range(1.0, 1e9),
    default=1e4,
)


class ScipyDense(DenseOutput):
    """The solvers' own dense outputs, one per scene, on σ of each scene's step; each built
    only when the driver asks for it (an event or the crest in that step), as scipy's
    ``solve_ivp`` does: DOP853's costs three more force evaluations."""

    __slots__ = ("built", "h", "solvers", "t0")

    def __init__(
        self, solvers: list[Any], t0: np.ndarray, h: np.ndarray, built: dict[int, Any]
    ) -> None:
        self.solvers, self.t0, self.h, self.built = solvers, t0, h, built

    def _part(self, solver: Any) -> Any:
        if id(solver) not in self.built:
            self.built[id(solver)] = solver.dense_output()
        return self.built[id(solver)]

    def __call__(self, sigma: float | np.ndarray) -> np.ndarray:
        times = self.t0 + np.broadcast_to(sigma, self.t0.shape) * self.h
        parts = [self._part(solver) for solver in self.solvers]
        return np.column_stack([part(time) for part, time in zip(parts, times, strict=True)])

    def take(self, index: np.ndarray) -> ScipyDense:
        solvers = [self.solvers[i] for i in index]
        return ScipyDense(solvers, self.t0[index], self.h[index], self.built)


@final
@attrs.frozen
class ScipyIVP(Integrator):
    """Each scene through a ``scipy.integrate`` solver (``OdeSolver``), one step at a time.

    The solver controls its own steps, with ``rtol`` and an absolute tolerance of
    ``rtol`` × the scale of each component (Rs, 1 rad, Vs), as the driver's control does
    for dopri5, so the two are compared like for like. The driver locates events on the
    solver's dense output; failure onset and the 180° hold start a new solver there.
    Loops over scenes in Python: a reference, not for speed.
    """

    name = "solve_ivp"
    version = "2"
    #: Events are looked for at the ends of each solver step, as scipy's solve_ivp does.
    event_samples = 2

    method: str = METHOD.field()
    rtol: float = attrs.evolve(RTOL, default=1e-10).field()
    max_steps: int = MAX_STEPS.field()
    max_seconds: float | None = MAX_SECONDS.field()
    longest_phase: float = LONGEST_PHASE.field()

    def initial_step(self, dynamics: Dynamics) -> np.ndarray:
        return np.full(dynamics.size, np.nan)  # the solvers choose their own

    def start(self, dynamics: Dynamics, t: np.ndarray, y: np.ndarray) -> StepperState:
        solvers = np.empty(dynamics.size, dtype=object)
        solvers[:] = [self._solver(dynamics, t, y, i) for i in range(dynamics.size)]
        return {"solver": solvers}

    def restart(
        self,
        dynamics: Dynamics,
        t: np.ndarray,
        y: np.ndarray,
        state: StepperState,
        index: np.ndarray,
    ) -> StepperState:
        for i in index:
            state["solver"][i] = self._solver(dynamics, t, y, int(i))
        return state

    def _solver(self, dynamics: Dynamics, t: np.ndarray, y: np.ndarray, i: int) -> Any:
        from scipy import integrate  # noqa: PLC0415 (scipy.integrate is slow to import)

        one = dynamics.take(np.array([i]))
        scale = one.component_scale(y.shape[0])[:, 0]

        def rates(_t: float, state: np.ndarray) -> np.ndarray:
            return one.rates(state[:, np.newaxis])[:, 0]

        solver_class = getattr(integrate, self.method)
        bound = float(t[i] + self.longest_phase * one.time_scale[0])
        return solver_class(
            rates, t[i], y[:, i].copy(), bound, rtol=self.rtol, atol=self.rtol * scale
        )

    def advance(
        self, dynamics: Dynamics, t: np.ndarray, y: np.ndarray, h: np.ndarray, state: StepperState
    ) -> Step:
        y_new, taken = np.empty_like(y), np.empty(y.shape[1])
        solvers = list(state["solver"])
        for i, solver in enumerate(solvers):
            if solver.status == "finished":
                raise IntegrationError(
                    f"solve_ivp: a scene unfinished after longest_phase={self.longest_phase:g} "
                    "Rs/Vs since its last restart; raise longest_phase "
                    "(--set integrator.longest_phase=MULTIPLE)"
                )
            # A trial step far too long (extreme plates) can overshoot to a state whose
            # force overflows; its non-finite error makes scipy reject it and shrink the
            # step, so the overflow is expected and silenced, never kept.
            with np.errstate(over="ignore", invalid="ignore"):
                solver.step()
            if solver.status == "failed":
                raise IntegrationError("solve_ivp: a step failed (the step size fell to zero)")
            y_new[:, i], taken[i] = solver.y, solver.t - solver.t_old
        return Step(y_new, taken, None, ScipyDense(solvers, t, taken, {}), state)
