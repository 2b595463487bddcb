"""The model against experiment: measured shots scored against the model's predictions
(docs/experiment.md).

>>> report = validate(simulation, sphere, plate, Shots.from_csv("shots.csv"))
>>> report.agreement, report.residual_speed_rms, report.disagreements
"""

from __future__ import annotations

from .validation import MEASURED, PREDICTED, Disagreement, ValidationReport, validate

__all__ = ["MEASURED", "PREDICTED", "Disagreement", "ValidationReport", "validate"]
