"""scipy's solve_ivp, one call per smooth phase: the side-by-side anchor."""

from __future__ import annotations

from typing import final

import attrs
import numpy as np
from scipy.integrate import solve_ivp

from plateimpact import (
    AT_REST,
    CONTACT_LOST,
    EVENT_OUTCOMES,
    KINEMATIC_STATE,
    LATERAL,
    OBLIQUITY,
    ONSET,
    PENETRATION,
    PERFORATED,
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

from ._settings import check_rtol

METHODS = ("DOP853", "RK45", "RK23", "LSODA", "Radau", "BDF")
#: A phase that has not ended after this many Rs/Vs is an error, not an outcome.
LONGEST_PHASE = 1e4


def _check_method(instance: object, attribute: attrs.Attribute, value: str) -> None:
    if value not in METHODS:
        raise ParameterError("method", f"method must be one of {', '.join(METHODS)}, got {value!r}")


@final
@attrs.frozen
class ScipyIVP(Integrator):
    """Each scene through ``scipy.integrate.solve_ivp``, one call per smooth phase.

    A phase ends at the first event (terminal events with direction +1 on the model's
    event margins, located by scipy to its own tolerance): failure onset and the 180° hold
    start a new phase with the new force law; contact loss, perforation and rest end the
    scene. The deepest point is recorded by a non-terminal event at θ = 90°. Tolerances:
    ``rtol`` and an absolute tolerance of ``rtol`` × the scale of each component (Rs, 1
    rad, Vs), as the built-in embedded RK does, so the two are compared like for like.

    This integrator loops over scenes in Python; it exists as a reference, not for speed.

    Parameters
    ----------
    method : one of DOP853 (default), RK45, RK23, LSODA, Radau, BDF
    rtol : float, in [1e-14, 1e-2]; default 1e-10
    """

    name = "solve_ivp"

    method: str = attrs.field(default="DOP853", validator=_check_method)
    rtol: float = attrs.field(default=1e-10, validator=check_rtol)

    def settings(self) -> dict[str, object]:
        return {"method": self.method, "rtol": self.rtol}

    def _integrate(self, model: ImpactModel, batch: SceneBatch, recorder: ResultRecorder) -> None:
        for i in range(batch.size):
            self._one_scene(model, batch.take(np.array([i])), i, recorder)

    def _one_scene(self, model, batch, scene_index, recorder) -> None:
        width = KINEMATIC_STATE + len(model.failure.state_names)
        y = np.zeros(width)  # failure state integrates zeros until onset sets it
        y[:KINEMATIC_STATE] = 0.0, 0.0, batch.impact_obliquity[0], batch.impact_speed[0]
        failed, held = np.zeros(1, bool), np.zeros(1, bool)
        scale = np.ones(width)
        scale[[PENETRATION, LATERAL]] = batch.radius[0]
        scale[SPEED] = batch.impact_speed[0]
        t, max_pen = 0.0, 0.0
        scene = np.array([scene_index])
        unit = batch.radius[0] / batch.impact_speed[0]
        recorder.sample(
            scene, np.zeros(1), *y[:KINEMATIC_STATE, None], y[KINEMATIC_STATE:, None], failed
        )
        rates = lambda _t, state: model.rates(state[:, None], failed, held, batch)[:, 0]  # noqa: E731

        def margin(kind):
            def event(_t, state):
                return model.event_margins(state[:, None], failed, held, batch)[kind, 0]

            event.terminal, event.direction = True, 1.0
            return event

        def deepest(_t, state):
            return state[OBLIQUITY] - 0.5 * np.pi

        deepest.terminal, deepest.direction = False, 1.0
        while True:
            # Events that can happen in this phase (the others are −inf margins).
            kinds = [CONTACT_LOST, AT_REST]
            kinds += [PERFORATED] if failed[0] else [ONSET]
            kinds += [] if held[0] else [TURNED_BACK]
            events = [margin(k) for k in kinds] + [deepest]
            if kinds.count(PERFORATED):
                # The margin without its θ < 90° mask, so scipy sees a continuous function.
                events[kinds.index(PERFORATED)] = self._perforation_event(model, failed, batch)
            # A trial step far too long (extreme plates) can overshoot to a state whose
            # force overflows; its non-finite error makes scipy reject it and shrink the
            # step, so the overflow is expected and silenced, never kept.
            with np.errstate(over="ignore", invalid="ignore"):
                solution = solve_ivp(
                    rates,
                    (t, t + LONGEST_PHASE * unit),
                    y,
                    method=self.method,
                    rtol=self.rtol,
                    atol=self.rtol * scale,
                    events=events,
                )
            recorder.stats["force_evaluations"] += solution.nfev
            recorder.stats["steps"] += solution.t.size - 1
            max_pen = max(max_pen, float(solution.y[PENETRATION].max()))
            if solution.y_events[-1].size:
                max_pen = max(max_pen, float(solution.y_events[-1][:, PENETRATION].max()))
            if recorder.record_trajectory:
                recorder.sample(
                    np.repeat(scene, solution.t.size - 1),
                    solution.t[1:],
                    *solution.y[:KINEMATIC_STATE, 1:],
                    solution.y[KINEMATIC_STATE:, 1:],
                    np.repeat(failed, solution.t.size - 1),
                )
            if solution.status != 1:
                raise IntegrationError(
                    f"solve_ivp: scene {scene_index} reached no outcome ({solution.message})"
                )
            fired = [j for j, k in enumerate(kinds) if solution.t_events[j].size]
            j = fired[0]
            t, y = float(solution.t_events[j][0]), solution.y_events[j][0].copy()
            kind = kinds[j]
            if kind == PERFORATED and y[OBLIQUITY] >= 0.5 * np.pi:
                continue  # passed the layer while moving outward: not a perforation
            if kind == ONSET:
                failed[0] = True
                state = y[KINEMATIC_STATE:, None]
                model.start_failure(
                    failed,
                    y[PENETRATION : PENETRATION + 1],
                    y[OBLIQUITY : OBLIQUITY + 1],
                    y[SPEED : SPEED + 1],
                    state,
                    batch,
                )
                y[KINEMATIC_STATE:] = state[:, 0]
                recorder.failed(
                    scene, np.array([t]), y[PENETRATION : PENETRATION + 1], y[LATERAL : LATERAL + 1]
                )
                continue
            if kind == TURNED_BACK:
                held[0] = True
                y[OBLIQUITY] = ImpactModel.MAX_OBLIQUITY
                continue
            outcome = EVENT_OUTCOMES[kind]
            exit_speed = 0.0 if outcome == Outcome.EMBEDMENT else y[SPEED]
            recorder.finish(
                scene,
                np.array([outcome]),
                np.array([exit_speed]),
                np.array([y[OBLIQUITY]]),
                np.array([t]),
                np.array([max_pen]),
            )
            return

    @staticmethod
    def _perforation_event(model, failed, batch):
        def event(_t, state):
            return model.perforation_margin(
                state[PENETRATION : PENETRATION + 1],
                state[OBLIQUITY : OBLIQUITY + 1],
                failed,
                batch,
            )[0]

        event.terminal, event.direction = True, 1.0
        return event
