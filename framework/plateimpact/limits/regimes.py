"""Regimes: what separates one outcome band from the next.

A band is a run of impact conditions with one outcome *and* one state of the plate, so
that a ricochet off a plate that failed (the thin-plate band of Figures 30-31) is a band
of its own beside the ricochet off an intact plate, and an embedment in a failed plate
beside one in an intact plate. Each regime has a small integer code, so that a batch's
regimes are one numpy expression and the finder compares integers.
"""

from __future__ import annotations

import attrs
import numpy as np

from ..model.results import BatchResult, Outcome


@attrs.frozen(order=True)
class Regime:
    """An outcome and whether the plate failed on the way to it."""

    outcome: Outcome = attrs.field(converter=Outcome)
    plate_failed: bool = attrs.field(converter=bool)

    @property
    def code(self) -> int:
        """2 × outcome + plate_failed: ricochet 2 and 3, embedment 4 and 5, perforation
        6 and 7 (a perforation without failure is impossible but keeps its code)."""
        return 2 * int(self.outcome) + int(self.plate_failed)

    @classmethod
    def of_code(cls, code: int) -> Regime:
        return cls(Outcome(int(code) // 2), bool(int(code) % 2))

    @property
    def label(self) -> str:
        """``ricochet``, ``ricochet after failure``, ``embedment``, ``embedment after
        failure`` or ``perforation``: as tables and figures name the band."""
        if self.outcome is Outcome.PERFORATION or not self.plate_failed:
            return self.outcome.label
        return f"{self.outcome.label} after failure"

    def to_json(self) -> dict[str, object]:
        """The outcome as ``run --json`` names it, and the plate's state."""
        return {"outcome": self.outcome.label, "plate_failed": self.plate_failed}


#: Every regime the model can reach, in the order figures and keys list them.
REGIMES = (
    Regime(Outcome.RICOCHET, False),
    Regime(Outcome.RICOCHET, True),
    Regime(Outcome.EMBEDMENT, False),
    Regime(Outcome.EMBEDMENT, True),
    Regime(Outcome.PERFORATION, True),
)
#: The regime codes as CF flags: ``flag_values`` and blank-separated ``flag_meanings``.
REGIME_FLAGS = ([r.code for r in REGIMES], " ".join(r.label.replace(" ", "_") for r in REGIMES))


def regime_codes(result: BatchResult) -> np.ndarray:
    """The regime code of every scene of ``result`` (see :attr:`Regime.code`)."""
    return 2 * np.asarray(result.outcome, dtype=np.int64) + np.asarray(result.plate_failed)
