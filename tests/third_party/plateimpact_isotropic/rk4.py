"""Classical fourth-order Runge–Kutta at a fixed step, as a plateimpact integrator."""

import attrs
import numpy as np

import plateimpact as pi

STEP = pi.Parameter(
    "step",
    "step as a fraction of Rs/Vs, the time to travel one radius at impact speed",
    range=pi.Range(0.0, 0.1, low_open=True),
    default=1e-2,
)


@attrs.frozen
class ClassicalRungeKutta(pi.Integrator):
    """RK4 at a fixed step, with a cubic Hermite dense output for the events."""

    name = "rk4"

    step: float = STEP.field()
    max_steps: int = pi.MAX_STEPS.field()

    def initial_step(self, dynamics: pi.Dynamics) -> np.ndarray:
        return self.step * dynamics.time_scale

    def start(self, dynamics: pi.Dynamics, t: np.ndarray, y: np.ndarray) -> pi.StepperState:
        return {"rates": dynamics.rates(y)}  # f(y): the next step's first stage

    def advance(
        self,
        dynamics: pi.Dynamics,
        t: np.ndarray,
        y: np.ndarray,
        h: np.ndarray,
        state: pi.StepperState,
    ) -> pi.Step:
        k1 = state["rates"]
        k2 = dynamics.rates(y + 0.5 * h * k1)
        k3 = dynamics.rates(y + 0.5 * h * k2)
        k4 = dynamics.rates(y + h * k3)
        y_new = y + h / 6.0 * (k1 + 2.0 * k2 + 2.0 * k3 + k4)
        f_new = dynamics.rates(y_new)
        return pi.Step(y_new, h, None, pi.hermite(y, y_new, k1, f_new, h), {"rates": f_new})

    def known_rates(self, state: pi.StepperState) -> np.ndarray:
        return state["rates"]  # the driver may reuse f(y) rather than evaluate it again
