"""The report's own integrator: constant-speed, constant-curvature segments (eqs 25–30)."""

from __future__ import annotations

from typing import final

import attrs
import numpy as np

from plateimpact import (
    ImpactModel,
    IntegrationError,
    Integrator,
    Outcome,
    ParameterError,
    ResultRecorder,
    SceneBatch,
)

from ._settings import check_max_steps

#: Default step, as a fraction of Rs/Vs (the time to travel one radius at impact speed).
DEFAULT_STEP = 1e-3
#: The finest step the tests and docs use.
FINEST_STEP = 1e-5


def _check_step(instance: object, attribute: attrs.Attribute, value: float) -> None:
    if not (isinstance(value, int | float) and 0.0 < value <= 0.1):
        raise ParameterError("step", f"step must be in (0, 0.1] of Rs/Vs, got {value!r}")


@final
@attrs.frozen
class Segment(Integrator):
    """NWC TP 5844's trajectory of segments with constant speed and curvature.

    Each segment lasts dt = ``step`` × Rs/Vs [s]. The force is evaluated at the start of
    the segment (step 1 of the report's procedure); the new speed is V' = V − F_D dt/m
    (eq 25) and the path turns by dθ = F_L dt/(m V) (eqs 26–28); the sphere then moves
    along the circular arc of that turn at the new speed V' ("from the new values for
    speed and curvature", step 4), which gives eqs 29–30 to first order. The method is
    first order in dt.

    Events are located inside a segment where the report's fixed step would overshoot:
    a segment is shortened to end exactly at the rest speed (so V never goes negative
    and the rest direction does not depend on where a step happened to fall), and to end
    at P = P* by linear interpolation (so failure starts at P*, not up to a step later).
    Contact loss and perforation are detected at the end of a segment.

    Parameters
    ----------
    step : float
        Segment duration as a fraction of Rs/Vs, in (0, 0.1]. Default 1e-3; the finest
        step documented and tested is 1e-5.
    max_steps : int
        Give up (IntegrationError) if a scene has not finished after this many segments.
    """

    name = "segment"

    step: float = attrs.field(default=DEFAULT_STEP, validator=_check_step)
    max_steps: int = attrs.field(default=20_000_000, validator=check_max_steps)

    def settings(self) -> dict[str, object]:
        return {"step": self.step, "max_steps": self.max_steps}

    @staticmethod
    def _advance(
        penetration: np.ndarray,
        lateral: np.ndarray,
        obliquity: np.ndarray,
        speed: np.ndarray,
        drag: np.ndarray,
        lift: np.ndarray,
        mass: np.ndarray,
        dt: np.ndarray,
    ) -> tuple[np.ndarray, ...]:
        """One segment: returns the new (P, Y, θ, V)."""
        new_speed = speed - drag * dt / mass  # eq 25
        turn = lift * dt / (mass * speed)  # eqs 26–27: dθ = V dt / r, r = m V² / F_L
        new_obliquity = np.minimum(obliquity + turn, ImpactModel.MAX_OBLIQUITY)  # eq 28
        turn = new_obliquity - obliquity
        # Chord of a circular arc of length V' dt turning by dθ (eqs 29–30 to first order).
        chord = new_speed * dt * np.sinc(turn / (2.0 * np.pi))
        heading = obliquity + 0.5 * turn
        return (
            penetration + chord * np.cos(heading),
            lateral + chord * np.sin(heading),
            new_obliquity,
            new_speed,
        )

    def _integrate(self, model: ImpactModel, batch: SceneBatch, recorder: ResultRecorder) -> None:
        scene = np.arange(batch.size)
        pen = np.zeros(batch.size)
        lat = np.zeros(batch.size)
        obl = batch.impact_obliquity.copy()
        spd = batch.impact_speed.copy()
        time = np.zeros(batch.size)
        failed = np.zeros(batch.size, dtype=bool)
        failure_state = model.new_failure_state(batch.size)
        max_pen = np.zeros(batch.size)
        nominal_dt = self.step * batch.radius / batch.impact_speed
        recorder.sample(scene, time, pen, lat, obl, spd, failure_state, failed)

        for _ in range(self.max_steps):
            drag, lift = model.forces(pen, obl, spd, failed, failure_state, batch)
            state_rates = model.failure_state_rates(
                pen, obl, spd, lift / (batch.mass * spd), failed, failure_state, batch
            )
            recorder.stats["force_evaluations"] += scene.size
            recorder.stats["steps"] += 1
            # Rest: the segment that reaches the rest speed ends on it exactly.
            slowing = drag > 0.0
            rest_dt = np.full(scene.size, np.inf)
            rest_dt[slowing] = (
                (spd - batch.rest_speed)[slowing] * batch.mass[slowing] / drag[slowing]
            )
            dt = np.minimum(nominal_dt, rest_dt)
            new = self._advance(pen, lat, obl, spd, drag, lift, batch.mass, dt)
            # Failure onset: shorten the segment to end at P = P* (linear in dt).
            onset = ~failed & (new[0] >= batch.onset_penetration)
            if onset.any():
                fraction = (batch.onset_penetration[onset] - pen[onset]) / (new[0] - pen)[onset]
                dt[onset] *= fraction
                new = self._advance(pen, lat, obl, spd, drag, lift, batch.mass, dt)
            at_rest = rest_dt <= dt
            pen, lat, obl, spd = new
            time = time + dt
            failure_state = failure_state + state_rates * dt
            np.maximum(max_pen, pen, out=max_pen)
            if onset.any():
                failed = failed | onset
                model.start_failure(onset, pen, obl, spd, failure_state, batch)
                recorder.failed(scene[onset], time[onset], pen[onset], lat[onset])
            recorder.sample(scene, time, pen, lat, obl, spd, failure_state, failed)

            status = model.classify(pen, obl, failed, at_rest, batch)
            done = status > 0
            if done.any():
                exit_speed = np.where(status[done] == Outcome.EMBEDMENT, 0.0, spd[done])
                recorder.finish(
                    scene[done], status[done], exit_speed, obl[done], time[done], max_pen[done]
                )
                keep = ~done
                if not keep.any():
                    return
                scene, batch = scene[keep], batch.take(keep)
                pen, lat, obl, spd = pen[keep], lat[keep], obl[keep], spd[keep]
                time, failed, max_pen = time[keep], failed[keep], max_pen[keep]
                failure_state = failure_state[:, keep]
                nominal_dt = nominal_dt[keep]
        raise IntegrationError(
            f"segment: {scene.size} scene(s) unfinished after max_steps={self.max_steps} "
            f"segments (first: scene {int(scene[0])}); raise max_steps or the step"
        )
