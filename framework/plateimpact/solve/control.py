"""Step sizes: error control for adaptive integrators, and landing on branch surfaces.

Per scene, as arrays: a step is accepted when the local error of every component is
below ``rtol`` times its scale (Rs for P and Y, 1 rad for θ and failure state, Vs for V,
or the component's own size if larger); the next step is h · 0.9 err^(−1/order), the
factor clipped to [0.2, 10] and not above 1 right after a rejection (Hairer, Nørsett &
Wanner II.4). Steps are at most 0.5 Rs/Vs, so that the first steps, taken while the force
is still ~0, cannot leap across the contact. docs/integrators.md gives the measurements.
"""

from __future__ import annotations

import numpy as np

from .dynamics import Dynamics
from .integrator import Integrator, Step, StepperState

SAFETY, MIN_FACTOR, MAX_FACTOR = 0.9, 0.2, 10.0
#: Largest step [fraction of Rs/Vs].
MAX_STEP = 0.5
#: Branch surfaces (docs/integrators.md): a step that would cross one is shortened to end
#: this fraction of the predicted way to it, so that it stays on the smooth side even
#: where the (Euler) prediction is off; the next step, finding the surface closer than
#: BRANCH_CROSSING of its length, crosses it with a step of that fraction.
BRANCH_APPROACH = 0.95
BRANCH_CROSSING = 0.02


class StepSizes:
    """The step of every active scene, and what the next one will be."""

    __slots__ = (
        "control",
        "crossing",
        "forced",
        "h",
        "just_rejected",
        "known_rates",
        "landing",
        "margins",
        "planned",
        "scale",
        "unit",
    )

    def __init__(
        self, integrator: Integrator, h: np.ndarray, scale: np.ndarray, unit: np.ndarray
    ) -> None:
        self.control = integrator.step_control()
        self.known_rates = integrator.known_rates
        self.h = h
        self.scale = scale  # each component's size (d, n)
        self.unit = unit  # Rs/Vs [s]
        self.just_rejected = np.zeros(h.size, bool)
        self.planned: np.ndarray | None = None
        self.landing: np.ndarray | None = None
        # The branch margins at the step's start (rows, n), the rows the step crosses on
        # purpose, and the scenes whose next step must cross a surface found just ahead.
        self.margins: np.ndarray | None = None
        self.crossing: np.ndarray | None = None
        self.forced = np.zeros(h.size, bool)

    def propose(self, dynamics: Dynamics, y: np.ndarray, state: StepperState) -> np.ndarray:
        """The steps to attempt now [s]."""
        if self.control is None:
            return self.h
        h = np.minimum(self.h, MAX_STEP * self.unit)
        self.planned = self.landing = self.margins = self.crossing = None
        if self.control.branch_landing:
            known = self.known_rates(state)
            rates = dynamics.rates(y) if known is None else known
            self.planned = h
            shortened, self.landing, self.margins, self.crossing = approach_branches(
                dynamics, y, h, rates
            )
            # A surface found just ahead by a rejected step (judge) is crossed now, by the
            # short step judge chose, whatever the prediction says.
            h = np.where(self.forced, h, shortened)
            self.landing &= ~self.forced
            self.crossing |= self.forced
            self.forced = np.zeros(h.size, bool)
        self.h = h
        return h

    def judge(self, step: Step, y: np.ndarray, dynamics: Dynamics) -> np.ndarray:
        """Which steps are accepted; sets the next step sizes."""
        finite = np.all(np.isfinite(step.y), axis=0)
        if self.control is None or step.error is None:
            return finite
        h = step.h
        scale = self.control.rtol * np.maximum(self.scale, np.maximum(np.abs(y), np.abs(step.y)))
        with np.errstate(invalid="ignore"):
            norm = np.max(np.abs(step.error) / scale, axis=0)
        ok = np.isfinite(norm) & finite & (norm <= 1.0)
        with np.errstate(divide="ignore", invalid="ignore"):
            factor = np.clip(
                SAFETY * norm ** (-1.0 / self.control.error_order), MIN_FACTOR, MAX_FACTOR
            )
        # A step that follows a rejection may not grow: where the error per step rises
        # along the path (a sphere turning ever faster before ricochet) this ends the
        # reject-accept cycle that otherwise costs every other step. Measured: 745 -> 640
        # force evaluations per scene at rtol 1e-10.
        factor = np.where(np.isfinite(factor), factor, MIN_FACTOR)
        factor = np.where(self.just_rejected | ~ok, np.minimum(factor, 1.0), factor)
        if self.landing is not None:  # after a step shortened to a branch surface, resume
            factor = np.where(self.landing & ok, self.planned / h, factor)
        self.just_rejected = ~ok
        self.h = h * factor
        if self.margins is not None:
            ok = self._refuse_unplanned_crossings(ok, step, dynamics)
        return ok

    def _refuse_unplanned_crossings(
        self, ok: np.ndarray, step: Step, dynamics: Dynamics
    ) -> np.ndarray:
        """Reject the steps that ended across a branch surface they did not plan to cross
        (the prediction of approach_branches missed it), and redo each onto the surface:
        to BRANCH_APPROACH of the way to it, located between the margins at the step's
        two ends, or, where it lies within BRANCH_CROSSING of the start, across it with a
        step of that fraction."""
        assert self.margins is not None and self.crossing is not None
        end = dynamics.branch_margins(step.y)
        crossed = (self.margins * end < 0.0) & ~self.crossing
        unplanned = crossed.any(axis=0) & ok
        if not unplanned.any():
            return ok
        with np.errstate(invalid="ignore", divide="ignore"):
            where = np.where(crossed, self.margins / (self.margins - end), np.inf).min(axis=0)
        near = unplanned & (where < BRANCH_CROSSING)
        short = unplanned & ~near
        self.h = np.where(near, BRANCH_CROSSING * step.h, self.h)
        self.h = np.where(short, BRANCH_APPROACH * where * step.h, self.h)
        self.forced = near
        self.just_rejected = self.just_rejected | unplanned
        return ok & ~unplanned

    def take(self, keep: np.ndarray) -> None:
        """Keep the scenes ``keep`` (boolean mask)."""
        self.h, self.unit = self.h[keep], self.unit[keep]
        self.scale, self.just_rejected = self.scale[:, keep], self.just_rejected[keep]
        self.forced = self.forced[keep]


def approach_branches(
    dynamics: Dynamics, y: np.ndarray, h: np.ndarray, rates: np.ndarray
) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
    """Steps shortened so as not to straddle a branch surface of the force, the scenes
    whose step now ends just short of one, the branch margins at ``y`` (rows, n) and the
    rows a step crosses on purpose (a surface within BRANCH_CROSSING of the step).

    Where the surface lies is predicted from the Euler step y + h f(y) (the sign change
    of :meth:`ImpactModel.branch_margins`, interpolated linearly): an O(h²) guess, which
    is why the step stops at BRANCH_APPROACH of the way and the crossing is a separate
    short step.
    """
    now = dynamics.branch_margins(y)
    ahead = dynamics.branch_margins(y + h * rates)
    with np.errstate(invalid="ignore", divide="ignore"):
        row_fraction = np.where(now * ahead < 0.0, now / (now - ahead), np.inf)
    fraction = row_fraction.min(axis=0)
    crossing = fraction < BRANCH_CROSSING
    landing = (fraction < 1.0) & ~crossing
    shortened = np.where(
        crossing, BRANCH_CROSSING * h, np.where(landing, BRANCH_APPROACH * fraction * h, h)
    )
    return shortened, landing, now, row_fraction < BRANCH_CROSSING
