"""The sweep's CSV, made a chunk of scenes at a time: the grid is run in chunks and each
chunk's rows are formatted column by column, so that memory holds one chunk however
large the grid, and the text is the same whatever the chunk size (a scene's result does
not depend on its batch)."""

from __future__ import annotations

import csv
import io
from collections.abc import Iterator

import attrs
import numpy as np

from ..base.untrusted import spreadsheet_safe
from ..model.batch import SceneBatch
from ..model.bodies import Plate, Sphere
from ..model.results import RESULT_FIELDS, BatchResult, Outcome
from ..model.scene import IMPACT_OBLIQUITY, IMPACT_SPEED
from ..run.simulation import Simulation

#: Columns of the sweep CSV: the plate's label, the impact, then the result fields.
SWEEP_COLUMNS = (
    "preset",
    IMPACT_SPEED.key,
    IMPACT_OBLIQUITY.key,
    *(RESULT_FIELDS[name].key for name in ("outcome", "exit_speed", "exit_obliquity")),
    *(RESULT_FIELDS[name].key for name in ("contact_time", "max_penetration", "plate_failed")),
)
#: Scenes per chunk: as fast as one batch of the whole grid (measured on 10^5 scenes:
#: 2,500 to 100,000 per chunk within 5%), a few MB each, and a hundred steps of the
#: progress bar on a million scenes.
SWEEP_CHUNK_SIZE = 10_000
#: Outcome labels by code (0, "not finished", never leaves an integrator).
_OUTCOME_LABELS = np.array(["", *(o.label for o in Outcome)])


def csv_field(text: str) -> str:
    """``text`` as a CSV writer writes it among other fields (quoted where it must be)."""
    buffer = io.StringIO()
    csv.writer(buffer, lineterminator="\n").writerow([spreadsheet_safe(text), ""])
    return buffer.getvalue()[: -len(",\n")]


def _floats(values: np.ndarray) -> list[str]:
    """Each value written exactly, as ``repr`` of a Python float writes it."""
    return list(map(repr, values.astype(float).tolist()))


def csv_rows(label: str, speed: np.ndarray, obliquity: np.ndarray, result: BatchResult) -> str:
    """The CSV rows of one chunk: ``label`` (already a CSV field), the impact speeds [m/s]
    and obliquities [deg] as typed, then the results in user units."""
    columns = [
        [label] * len(result),
        _floats(speed),
        _floats(obliquity),
        _OUTCOME_LABELS[result.outcome].tolist(),
        _floats(result.exit_speed),
        _floats(result.exit_obliquity / RESULT_FIELDS["exit_obliquity"].scale),
        _floats(result.contact_time),
        _floats(result.max_penetration / RESULT_FIELDS["max_penetration"].scale),
        np.where(result.plate_failed, "true", "false").tolist(),
    ]
    return "".join(f"{row}\n" for row in map(",".join, zip(*columns, strict=True)))


@attrs.define
class Sweep:
    """Every (obliquity, speed) pair of ``speeds`` [m/s] and ``obliquities`` [deg, as
    typed] for one sphere and plate, obliquity-major; ``counts`` holds the outcomes of
    the scenes run so far (by code)."""

    simulation: Simulation
    sphere: Sphere
    plate: Plate
    label: str
    speeds: np.ndarray
    obliquities: np.ndarray
    counts: np.ndarray = attrs.field(factory=lambda: np.zeros(len(Outcome) + 1, dtype=np.int64))

    @property
    def size(self) -> int:
        """Scenes in the grid."""
        return self.speeds.size * self.obliquities.size

    def csv_chunks(self, chunk_size: int | None = None) -> Iterator[str]:
        """The CSV text: the header, then the rows of each chunk of ``chunk_size``
        scenes (default :data:`SWEEP_CHUNK_SIZE`), each chunk run only when asked for.
        The grid is checked now."""
        chunk_size = SWEEP_CHUNK_SIZE if chunk_size is None else chunk_size
        chunks = SceneBatch.grid_chunks(
            self.sphere,
            self.plate,
            self.speeds,
            self.obliquities * IMPACT_OBLIQUITY.scale,
            chunk_size,
        )
        return self._texts(chunks, chunk_size)

    def _texts(self, chunks: Iterator[SceneBatch], chunk_size: int) -> Iterator[str]:
        yield ",".join(SWEEP_COLUMNS) + "\n"
        label = csv_field(self.label)
        for start, batch in zip(range(0, self.size, chunk_size), chunks, strict=True):
            result = self.simulation.run_batch(batch)
            self.counts += np.bincount(result.outcome, minlength=self.counts.size)
            # echo the values as typed, not their round trip via SI
            row, column = np.divmod(np.arange(start, start + batch.size), self.speeds.size)
            yield csv_rows(label, self.speeds[column], self.obliquities[row], result)
