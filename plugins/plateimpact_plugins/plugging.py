"""Plugging failure (report eqs 8–15): material beyond a fixed plane stops resisting."""

from __future__ import annotations

from typing import final

import attrs
import numpy as np

from plateimpact import FailureModel, ResistanceLaw, SceneBatch, contact_force


@final
@attrs.frozen
class Plugging(FailureModel):
    """At P = P* the plate separates along the ring at α* on the sphere.

    The ring's depth at onset, h = Rs cos α* + P* − Rs (eq 8 with P = P*), defines a
    plane fixed in the plate (α* is measured "with respect to the plate orientation").
    Material deeper than h is gone: the relieved force F′ is eq 1 on the part of the
    contact surface below that plane (eqs 9–14, i.e. eqs 2–6 with P − h for P), and the
    net force is F* − F′ (eq 15), drag and lift subtracted as vectors (each part has its
    own inclination). When h < 0 the ring is still above the front surface at failure
    and the whole contact region separates: h is taken as 0 (docs/model.md).

    Perforation is complete when the front layer 0 < z < h no longer touches the
    forward hemisphere: P − h >= Rs (1 + sin θ) while θ < 90°.
    """

    name = "plugging"

    def onset_penetration(self, batch: SceneBatch) -> np.ndarray:
        return batch.critical_penetration

    def prepare(self, batch: SceneBatch) -> dict[str, np.ndarray]:
        onset = self.onset_penetration(batch)
        ring_depth = batch.radius * np.cos(batch.failure_angle) + onset - batch.radius  # eq 8
        return {"failure_plane_depth": np.maximum(ring_depth, 0.0)}

    def force_change(
        self,
        penetration: np.ndarray,
        obliquity: np.ndarray,
        speed: np.ndarray,
        batch: SceneBatch,
        law: ResistanceLaw,
    ) -> tuple[np.ndarray, np.ndarray]:
        below_plane = penetration - batch.failure_plane_depth
        relieved_drag, relieved_lift = contact_force(law, below_plane, obliquity, speed, batch)
        return -relieved_drag, -relieved_lift  # eq 15: F = F* − F′

    def perforation_margin(
        self, penetration: np.ndarray, obliquity: np.ndarray, batch: SceneBatch
    ) -> np.ndarray:
        # Depth of the forward hemisphere's shallowest point below the failure plane.
        reach = batch.radius * (1.0 + np.sin(np.minimum(obliquity, 0.5 * np.pi)))
        return penetration - batch.failure_plane_depth - reach
