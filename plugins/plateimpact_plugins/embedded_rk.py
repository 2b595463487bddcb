"""Adaptive embedded Runge–Kutta over a batch of scenes, with dense output and events."""

from __future__ import annotations

from typing import ClassVar

import attrs
import numpy as np

from plateimpact import (
    EVENT_OUTCOMES,
    KINEMATIC_STATE,
    LATERAL,
    OBLIQUITY,
    ONSET,
    PENETRATION,
    SPEED,
    TURNED_BACK,
    ImpactModel,
    IntegrationError,
    Integrator,
    Outcome,
    ParameterError,
    ResultRecorder,
    SceneBatch,
)

from ._settings import check_max_steps, check_rtol
from .event_location import EVENT_SAMPLES, dense_state, first_event, sample_step

SAFETY, MIN_FACTOR, MAX_FACTOR = 0.9, 0.2, 10.0
#: Steps are limited to this fraction of Rs/Vs so that the first steps, taken while the
#: force is still ~0, cannot leap across the contact.
MAX_STEP = 0.5
FIRST_STEP = 1e-2
#: Branch surfaces (docs/integrators.md): a step that would cross one is shortened to end
#: this fraction of the predicted way to it, so that it stays on the smooth side even
#: where the (Euler) prediction is off; the next step, finding the surface closer than
#: BRANCH_CROSSING of its length, crosses it with a step of that fraction.
BRANCH_APPROACH = 0.95
BRANCH_CROSSING = 0.02


def _combine(weights: np.ndarray, stages: np.ndarray) -> np.ndarray:
    """Σ_j weights[j] · stages[j], element-wise in a fixed order, skipping zero weights
    (so that a scene's result never depends on which other scenes share its batch)."""
    total = np.zeros_like(stages[0])
    for weight, stage in zip(weights, stages, strict=False):
        if weight != 0.0:
            total += weight * stage
    return total


def _check_bool(instance: object, attribute: attrs.Attribute, value: object) -> None:
    if not isinstance(value, bool):
        raise ParameterError(
            attribute.name, f"{attribute.name} must be true or false, got {value!r}"
        )


def _check_fixed_step(instance: object, attribute: attrs.Attribute, value: float | None) -> None:
    if value is not None and not (isinstance(value, int | float) and 0.0 < value <= MAX_STEP):
        raise ParameterError(
            "fixed_step", f"fixed_step must be in (0, {MAX_STEP}] of Rs/Vs or None, got {value!r}"
        )


@attrs.frozen
class EmbeddedRungeKutta(Integrator):
    """Abstract: an explicit embedded Runge–Kutta pair with FSAL and dense output.

    A subclass is data: the tableau ``C``, ``A``, ``B``, the error weights ``E`` (over all
    stages, the last being the FSAL stage), the dense-output matrix ``P`` (stage weights
    as polynomials in σ = (t − tn)/h, coefficients of σ, σ², ...), and ``error_order``.

    Every scene has its own step size h, controlled so that the local error of every
    state component stays below ``rtol`` × its scale (Rs for P and Y, 1 rad for θ and
    failure state, Vs for V, or the component's own size if larger). All scenes advance
    together, one step per iteration, as numpy arrays; finished scenes leave the set.

    Events (``ImpactModel.event_margins``) are located in every accepted step on the dense
    output: sampled at EVENT_SAMPLES, then refined in the first sub-step where a margin
    goes from < 0 to >= 0. The step is cut there and the integration restarts with the
    new force law (failure onset, θ held at 180°) or the scene ends (contact lost,
    perforation, rest). The maximum penetration is located the same way, where θ
    crosses 90°.

    Branch surfaces (``ImpactModel.branch_margins``), where the force is continuous but
    not smooth, are not stepped across: a step predicted to cross one is shortened to
    end just before it, and the next crosses it with a short step (``branch_landing``;
    docs/integrators.md, "branch surfaces").
    """

    C: ClassVar[np.ndarray]
    A: ClassVar[np.ndarray]
    B: ClassVar[np.ndarray]
    E: ClassVar[np.ndarray]
    P: ClassVar[np.ndarray]
    error_order: ClassVar[int]

    rtol: float = attrs.field(default=1e-8, validator=check_rtol)
    max_steps: int = attrs.field(default=200_000, validator=check_max_steps)
    fixed_step: float | None = attrs.field(default=None, validator=_check_fixed_step)
    branch_landing: bool = attrs.field(default=True, validator=_check_bool)

    def settings(self) -> dict[str, object]:
        return {
            "rtol": self.rtol,
            "max_steps": self.max_steps,
            "fixed_step": self.fixed_step,
            "branch_landing": self.branch_landing,
        }

    @staticmethod
    def _approach_branches(
        model: ImpactModel,
        y: np.ndarray,
        h: np.ndarray,
        rates: np.ndarray,
        failed: np.ndarray,
        batch: SceneBatch,
    ) -> tuple[np.ndarray, np.ndarray]:
        """Steps shortened so as not to straddle a branch surface of the force, and the
        scenes whose step now ends just short of one.

        Where the surface lies is predicted from the Euler step y + h f(y) (the sign
        change of :meth:`ImpactModel.branch_margins`, interpolated linearly): an O(h²)
        guess, which is why the step stops at BRANCH_APPROACH of the way and the
        crossing is a separate short step.
        """
        now = model.branch_margins(y, failed, batch)
        ahead = model.branch_margins(y + h * rates, failed, batch)
        with np.errstate(invalid="ignore", divide="ignore"):
            fraction = np.where(now * ahead < 0.0, now / (now - ahead), np.inf).min(axis=0)
        crossing = fraction < BRANCH_CROSSING
        landing = (fraction < 1.0) & ~crossing
        shortened = np.where(
            crossing, BRANCH_CROSSING * h, np.where(landing, BRANCH_APPROACH * fraction * h, h)
        )
        return shortened, landing

    def _dense_coefficients(self, h: np.ndarray, stages: np.ndarray) -> np.ndarray:
        """Coefficients c_q = h Σ_j P[j, q] k_j of the dense output, shape (Q, d, n), so that
        y(tn + σh) = yn + σ(c_0 + σ(c_1 + ...)). Built once per step, stage by stage in a
        fixed order (a scene's values never depend on the rest of its batch)."""
        coefficients = np.zeros((self.P.shape[1],) + stages.shape[1:])
        for j in range(stages.shape[0]):
            for q, weight in enumerate(self.P[j]):
                if weight != 0.0:
                    coefficients[q] += weight * stages[j]
        return coefficients * h

    def _integrate(self, model: ImpactModel, batch: SceneBatch, recorder: ResultRecorder) -> None:
        n = batch.size
        width = KINEMATIC_STATE + len(model.failure.state_names)
        scene = np.arange(n)
        y = np.zeros((width, n))  # failure state integrates zeros until onset sets it
        y[PENETRATION], y[LATERAL] = 0.0, 0.0
        y[OBLIQUITY], y[SPEED] = batch.impact_obliquity, batch.impact_speed
        t = np.zeros(n)
        failed, held = np.zeros(n, bool), np.zeros(n, bool)
        max_pen = np.zeros(n)
        unit = batch.radius / batch.impact_speed  # Rs/Vs [s]
        h = (FIRST_STEP if self.fixed_step is None else self.fixed_step) * unit
        char = np.ones((width, n))
        char[PENETRATION] = char[LATERAL] = batch.radius
        char[SPEED] = batch.impact_speed
        k_first = model.rates(y, failed, held, batch)
        recorder.stats["force_evaluations"] += n
        recorder.stats["accepted_steps"] = recorder.stats["rejected_steps"] = 0
        recorder.sample(scene, t, *y[:KINEMATIC_STATE], y[KINEMATIC_STATE:], failed)
        stages = np.empty((len(self.C) + 1, width, n))
        exponent = -1.0 / self.error_order
        just_rejected = np.zeros(n, bool)

        approach = self.branch_landing and self.fixed_step is None
        for _ in range(self.max_steps):
            recorder.stats["steps"] += 1
            if approach:
                planned = h
                h, landing = self._approach_branches(model, y, h, k_first, failed, batch)
            stages = stages[:, :, : y.shape[1]]
            stages[0] = k_first
            for i in range(1, len(self.C)):
                stage_y = y + h * _combine(self.A[i, :i], stages)
                stages[i] = model.rates(stage_y, failed, held, batch)
            y_new = y + h * _combine(self.B, stages)
            stages[-1] = model.rates(y_new, failed, held, batch)
            recorder.stats["force_evaluations"] += len(self.C) * y.shape[1]
            error = h * _combine(self.E, stages)
            scale = self.rtol * np.maximum(char, np.maximum(np.abs(y), np.abs(y_new)))
            with np.errstate(invalid="ignore"):
                norm = np.max(np.abs(error) / scale, axis=0)
            ok = np.isfinite(norm) & np.all(np.isfinite(y_new), axis=0) & (norm <= 1.0)
            if self.fixed_step is not None:  # no error control: every finite step stands
                ok = np.all(np.isfinite(y_new), axis=0)
                norm = np.ones_like(norm)
            with np.errstate(divide="ignore", invalid="ignore"):
                factor = np.clip(SAFETY * norm**exponent, MIN_FACTOR, MAX_FACTOR)
            # A step that follows a rejection may not grow (Hairer, Nørsett & Wanner II.4):
            # where the error per step rises along the path (a sphere turning ever faster
            # before ricochet) this ends the reject–accept cycle that otherwise costs every
            # other step. Measured: 745 → 640 force evaluations per scene at rtol 1e-10.
            factor = np.where(np.isfinite(factor), factor, MIN_FACTOR)
            factor = np.where(just_rejected | ~ok, np.minimum(factor, 1.0), factor)
            if approach:  # after a step shortened to a branch surface, resume the plan
                factor = np.where(landing & ok, planned / h, factor)
            just_rejected = ~ok
            accepted = int(np.count_nonzero(ok))
            recorder.stats["accepted_steps"] += accepted
            recorder.stats["rejected_steps"] += ok.size - accepted
            if not accepted:
                h = h * factor
                continue

            # Accepted scenes: sample the step, find the first event in it.
            idx = np.flatnonzero(ok)
            sub = batch if accepted == ok.size else batch.take(idx)
            y0, h0 = y[:, idx], h[idx]
            k = self._dense_coefficients(h0, stages[:, :, idx])
            samples, margins = sample_step(model, y0, y_new[:, idx], k, failed[idx], held[idx], sub)
            event_sigma, event_kind, crest_sigma = first_event(
                model, samples, margins, y0, k, failed[idx], held[idx], sub
            )
            hit = np.isfinite(event_sigma)
            end_sigma = np.where(hit, event_sigma, 1.0)
            y_end = np.where(hit, dense_state(y0, k, end_sigma), y_new[:, idx])
            t_end = t[idx] + end_sigma * h0

            # Maximum penetration: P at the samples, at the step's end, and where θ
            # crosses 90° upward (the crest) if that comes before the end.
            inside = EVENT_SAMPLES[:, np.newaxis] <= end_sigma
            peak = np.max(np.where(inside, samples[PENETRATION], -np.inf), axis=0)
            peak = np.maximum(peak, y_end[PENETRATION])
            crest_rows = np.flatnonzero(crest_sigma < end_sigma)
            if crest_rows.size:
                crest = dense_state(y0[:, crest_rows], k[:, :, crest_rows], crest_sigma[crest_rows])
                peak[crest_rows] = np.maximum(peak[crest_rows], crest[PENETRATION])
                if recorder.record_trajectory:  # the deepest point belongs to the path
                    at = idx[crest_rows]
                    recorder.sample(
                        scene[at],
                        t[at] + crest_sigma[crest_rows] * h0[crest_rows],
                        *crest[:KINEMATIC_STATE],
                        crest[KINEMATIC_STATE:],
                        failed[at],
                    )
            max_pen[idx] = np.maximum(max_pen[idx], peak)
            if recorder.record_trajectory:
                for j in range(1, EVENT_SAMPLES.size):
                    keep = EVENT_SAMPLES[j] < end_sigma
                    if keep.any():
                        s_y = samples[:, j, keep]
                        recorder.sample(
                            scene[idx[keep]],
                            t[idx[keep]] + EVENT_SAMPLES[j] * h0[keep],
                            *s_y[:KINEMATIC_STATE],
                            s_y[KINEMATIC_STATE:],
                            failed[idx[keep]],
                        )
                recorder.sample(
                    scene[idx],
                    t_end,
                    *y_end[:KINEMATIC_STATE],
                    y_end[KINEMATIC_STATE:],
                    failed[idx],
                )

            # Advance: full steps keep the FSAL stage; cut steps restart from the event.
            y[:, idx], t[idx] = y_end, t_end
            k_first[:, idx] = stages[-1][:, idx]
            h = h * factor
            status = np.zeros(y.shape[1], dtype=np.int8)
            events = idx[hit]
            kinds = event_kind[hit]
            for kind, outcome in EVENT_OUTCOMES.items():
                status[events[kinds == kind]] = outcome
            onset = events[kinds == ONSET]
            if onset.size:
                mask = np.zeros(y.shape[1], bool)
                mask[onset] = True
                failed = failed | mask
                state = y[KINEMATIC_STATE:]
                model.start_failure(mask, y[PENETRATION], y[OBLIQUITY], y[SPEED], state, batch)
                y[KINEMATIC_STATE:] = state
                recorder.failed(scene[onset], t[onset], y[PENETRATION, onset], y[LATERAL, onset])
            turned = events[kinds == TURNED_BACK]
            if turned.size:
                held[turned] = True
                y[OBLIQUITY, turned] = ImpactModel.MAX_OBLIQUITY
            restart = events[(kinds == ONSET) | (kinds == TURNED_BACK)]
            if restart.size:
                k_first[:, restart] = model.rates(
                    y[:, restart], failed[restart], held[restart], batch.take(restart)
                )
                recorder.stats["force_evaluations"] += restart.size

            done = status > 0
            if done.any():
                exit_speed = np.where(status[done] == Outcome.EMBEDMENT, 0.0, y[SPEED, done])
                recorder.finish(
                    scene[done],
                    status[done],
                    exit_speed,
                    y[OBLIQUITY, done],
                    t[done],
                    max_pen[done],
                )
                keep = ~done
                if not keep.any():
                    return
                scene, batch = scene[keep], batch.take(keep)
                y, t, h, k_first = y[:, keep], t[keep], h[keep], k_first[:, keep]
                failed, held, max_pen = failed[keep], held[keep], max_pen[keep]
                just_rejected = just_rejected[keep]
                char, unit = char[:, keep], unit[keep]
            h = np.minimum(h, MAX_STEP * unit)
            if self.fixed_step is not None:
                h = self.fixed_step * unit
        raise IntegrationError(
            f"{self.name}: {scene.size} scene(s) unfinished after max_steps={self.max_steps} "
            f"steps (first: scene {int(scene[0])}); raise max_steps or rtol"
        )
