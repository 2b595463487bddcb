"""Shot data: oblique firings, what each did and what was measured, from CSV or columns.

A shot is one firing: impact speed [m/s] and obliquity [deg], and whether it perforated,
told by any of its outcome (ricochet, embedment, perforation), a ``perforated`` 0/1
(go/no-go data) or its residual speed [m/s]; optionally the exit obliquity [deg], the
sphere's radius [mm] and mass [g] when they differ from shot to shot, a weight and a
free-text source. The CSV header names the columns, in any order:

    impact_speed_m_s,impact_obliquity_deg[,outcome][,perforated][,residual_speed_m_s]
    [,exit_obliquity_deg][,radius_mm][,mass_g][,weight][,source]

with at least one of ``outcome``, ``perforated`` and ``residual_speed_m_s``. Lines
starting with ``#`` are comments; other columns are ignored; a UTF-8 byte order mark and
CRLF line ends are read. The file is read a row at a time (:mod:`.shot_reader`): the
first bad value raises :class:`~plateimpact.base.errors.ShotDataError` at once, with one line
naming the file, line, column and value (and how many of the next 10,000 rows are bad);
what the outcome, ``perforated`` and residual speed say must agree; a set holds at most
:data:`MAX_SHOTS` shots (docs/calibration.md, "1. Shot data").
"""

from __future__ import annotations

import csv
import io
import math
import os
from collections.abc import Mapping, Sequence

import attrs
import numpy as np

from ..base.errors import ParameterError, ShotDataError
from ..base.parameters import Parameter
from ..base.untrusted import check_input, spreadsheet_safe
from ..model.batch import SceneBatch
from ..model.bodies import MASS, RADIUS, Plate, Sphere, check_density
from ..model.results import RESULT_FIELDS, Outcome
from ..model.scene import IMPACT_OBLIQUITY
from .shot_reader import (
    MAX_SHOTS,
    ShotColumns,
    ShotLabels,
    check_all,
    check_count,
    column_records,
    csv_records,
)
from .shot_rows import COLUMNS, PERFORATION_COLUMNS, REQUIRED_COLUMNS, RESIDUAL_SPEED, check_columns

__all__ = [
    "COLUMNS",
    "MAX_SHOTS",
    "PERFORATION_COLUMNS",
    "REQUIRED_COLUMNS",
    "RESIDUAL_SPEED",
    "ShotLabels",
    "Shots",
]

EXIT_OBLIQUITY = RESULT_FIELDS["exit_obliquity"]


def _nan_like(instance: Shots) -> np.ndarray:
    return np.full(len(instance), math.nan)


@attrs.frozen(eq=False)
class Shots:
    """Shot data in SI units, one entry per shot.

    Attributes
    ----------
    impact_speed : numpy.ndarray
        Vs [m/s], in the range of ``plateimpact.model.scene.IMPACT_SPEED``.
    impact_obliquity : numpy.ndarray
        θs [rad], in [0, π/2).
    residual_speed : numpy.ndarray
        Speed when contact ended [m/s], in [0, Vs]: through the plate for a perforation,
        the ricochet's exit speed, 0 for a shot that did not perforate; NaN where not
        recorded.
    exit_obliquity : numpy.ndarray
        [rad], NaN where not recorded.
    outcome : numpy.ndarray
        :class:`~plateimpact.Outcome` values, 0 where only go/no-go is known.
    labels : sequence of str
        Where each shot came from (``shots.csv line 7``), for error messages: a tuple, or
        from a file a ``ShotLabels`` (line numbers, each label made when asked).
    source : str
        The file (or ``"shots"``), for error messages about the whole set.
    perforated : numpy.ndarray
        bool: whether each shot perforated. Default: the outcome where known, else a
        residual speed > 0.
    radius, mass : numpy.ndarray
        The sphere of each shot, Rs [m] and m [kg]; NaN where the sphere of the command
        (or of :meth:`scenes`) applies.
    weight : numpy.ndarray
        Weight of each shot in fits and scores, >= 0 (default 1).
    notes : tuple of str
        The free-text ``source`` column of each shot ("" where absent).
    """

    impact_speed: np.ndarray
    impact_obliquity: np.ndarray
    residual_speed: np.ndarray
    exit_obliquity: np.ndarray
    outcome: np.ndarray
    labels: Sequence[str]
    source: str = "shots"
    perforated: np.ndarray = attrs.field(kw_only=True)
    radius: np.ndarray = attrs.field(kw_only=True, default=attrs.Factory(_nan_like, True))
    mass: np.ndarray = attrs.field(kw_only=True, default=attrs.Factory(_nan_like, True))
    weight: np.ndarray = attrs.field(kw_only=True)
    notes: tuple[str, ...] = attrs.field(kw_only=True)

    @perforated.default
    def _perforated_from_outcome_or_speed(self) -> np.ndarray:
        if np.shape(self.outcome) != np.shape(self.residual_speed):
            return np.zeros(len(self), bool)  # __attrs_post_init__ names the mismatch
        known = self.outcome != 0
        return np.where(known, self.outcome == Outcome.PERFORATION, self.residual_speed > 0.0)

    @weight.default
    def _unit_weights(self) -> np.ndarray:
        return np.ones(len(self))

    @notes.default
    def _no_notes(self) -> tuple[str, ...]:
        return ("",) * len(self)

    def __attrs_post_init__(self) -> None:
        sizes = {
            name: len(getattr(self, name))
            for name in ("impact_obliquity", "residual_speed", "exit_obliquity", "outcome")
            + ("labels", "perforated", "radius", "mass", "weight", "notes")
        }
        wrong = {name: size for name, size in sizes.items() if size != len(self)}
        if wrong:
            raise ShotDataError(
                f"{self.source}: {len(self)} impact speeds but {wrong} (one entry per shot)"
            )
        check_count(self.source, len(self))

    def __len__(self) -> int:
        return int(np.size(self.impact_speed))

    def take(self, index: np.ndarray) -> Shots:
        """The shots at ``index`` (a boolean mask or integer indices)."""
        kept = np.arange(len(self))[index]
        return Shots(
            self.impact_speed[kept],
            self.impact_obliquity[kept],
            self.residual_speed[kept],
            self.exit_obliquity[kept],
            self.outcome[kept],
            _take_labels(self.labels, kept),
            self.source,
            perforated=self.perforated[kept],
            radius=self.radius[kept],
            mass=self.mass[kept],
            weight=self.weight[kept],
            notes=tuple(self.notes[i] for i in kept),
        )

    def normal_incidence(self) -> Shots:
        """The shots fired at obliquity 0 (the ones the report calibrates a and b on)."""
        return self.take(self.impact_obliquity == 0.0)

    def groups_by_obliquity(self) -> dict[float, Shots]:
        """The shots of each impact obliquity [rad], in increasing obliquity (each group
        in file order; one sort, however many obliquities)."""
        obliquities, group = np.unique(self.impact_obliquity, return_inverse=True)
        order = np.argsort(group.reshape(-1), kind="stable")
        starts = np.searchsorted(group.reshape(-1)[order], np.arange(obliquities.size + 1))
        return {
            float(obliquity): self.take(order[starts[k] : starts[k + 1]])
            for k, obliquity in enumerate(obliquities)
        }

    def at_one_obliquity(self, what: str) -> Shots:
        """These shots, when they are all at one impact obliquity (a V50 or a DRI fit is
        of one); :class:`ShotDataError` naming the obliquities otherwise. ``what`` names
        the fit (``"a V50"``)."""
        found = np.unique(self.impact_obliquity)
        if found.size > 1:
            listed = ", ".join(f"{x / IMPACT_OBLIQUITY.scale:g}" for x in found[:6])
            more = ", ..." if found.size > 6 else ""
            raise ShotDataError(
                f"{self.source}: shots at {found.size} obliquities ({listed}{more} deg): "
                f"{what} is of one obliquity; fit each of shots.groups_by_obliquity()"
            )
        return self

    def spheres(self, sphere: Sphere) -> tuple[np.ndarray, np.ndarray]:
        """(radius [m], mass [kg]) of each shot: its own where given, else ``sphere``'s;
        :class:`ShotDataError` naming the shot whose sphere is not a solid's density."""
        radius = np.where(np.isnan(self.radius), sphere.radius, self.radius)
        mass = np.where(np.isnan(self.mass), sphere.mass, self.mass)
        try:
            check_density(radius, mass)
        except ParameterError:
            for i in range(len(self)):  # only to name the first bad shot
                try:
                    check_density(radius[i], mass[i])
                except ParameterError as exc:
                    raise ShotDataError(f"{self.labels[i]}: {exc}") from None
        return radius, mass

    def scenes(self, sphere: Sphere, plate: Plate) -> SceneBatch:
        """One scene per shot: its impact, its own sphere where the file gives a radius
        or mass (else ``sphere``'s), and ``plate``."""
        radius, mass = self.spheres(sphere)
        columns = {
            "radius": radius,
            "mass": mass,
            "thickness": np.full(len(self), plate.thickness),
            "impact_speed": self.impact_speed,
            "impact_obliquity": self.impact_obliquity,
        }
        columns.update({name: np.full(len(self), value) for name, value in plate.constants})
        return SceneBatch(columns)

    @classmethod
    def from_columns(
        cls, columns: Mapping[str, Sequence[object]], *, source: str = "shots"
    ) -> Shots:
        """Shots from columns named as in the CSV header, in user units (m/s, deg, mm, g).

        Values may be numbers or strings; empty optional values mean "not recorded".
        Errors name the row by index: ``shots row 3, column ...``.
        """
        lengths = {len(values) for values in columns.values()}
        if len(lengths) > 1:
            raise ShotDataError(f"{source}: columns differ in length: {sorted(lengths)}")
        check_count(source, lengths.pop() if lengths else 0)
        check_columns(source, list(columns))
        return _of_rows(check_all(column_records(columns), source, "row"), source, "row")

    @classmethod
    def from_csv(cls, path: str | os.PathLike[str]) -> Shots:
        """Shots from a CSV file (see the module's description of the columns), read a
        row at a time."""
        source = os.fspath(path)
        check_input(source, source, ShotDataError)
        try:
            with open(source, encoding="utf-8-sig", newline="") as handle:  # BOM allowed
                return _of_rows(check_all(csv_records(handle, source), source, "line"), source)
        except (OSError, UnicodeDecodeError) as exc:
            reason = exc.strerror if isinstance(exc, OSError) else "not UTF-8 text"
            raise ShotDataError(f"{source}: cannot read: {reason}") from None

    @classmethod
    def from_csv_text(cls, text: str, *, source: str = "shots") -> Shots:
        """Shots from the text of a CSV file; ``source`` names it in error messages."""
        handle = io.StringIO(text.removeprefix("\ufeff"), newline="")
        return _of_rows(check_all(csv_records(handle, source), source, "line"), source)

    def to_csv_text(self, comments: Sequence[str] = ()) -> str:
        """The shots as CSV in user units, ``# comment`` lines first: the columns that
        carry something, each number written so that it reads back exactly."""
        recorded = {
            "outcome": bool((self.outcome != 0).any()),
            # Needed only where neither the outcome nor a residual speed tells it.
            "perforated": bool(((self.outcome == 0) & np.isnan(self.residual_speed)).any()),
            RESIDUAL_SPEED.key: bool(np.isfinite(self.residual_speed).any()),
            EXIT_OBLIQUITY.key: bool(np.isfinite(self.exit_obliquity).any()),
            RADIUS.key: bool(np.isfinite(self.radius).any()),
            MASS.key: bool(np.isfinite(self.mass).any()),
            "weight": bool((self.weight != 1.0).any()),
            "source": any(self.notes),
        }
        header = [c for c in COLUMNS if recorded.get(c, True)]
        buffer = io.StringIO()
        for comment in comments:
            buffer.write(f"# {comment}\n")
        writer = csv.writer(buffer, lineterminator="\n")
        writer.writerow(header)
        for i in range(len(self)):
            cells = {
                REQUIRED_COLUMNS[0]: _exact(self.impact_speed[i]),
                REQUIRED_COLUMNS[1]: _exact(self.impact_obliquity[i], IMPACT_OBLIQUITY),
                "outcome": Outcome(int(self.outcome[i])).label if self.outcome[i] else "",
                "perforated": "1" if self.perforated[i] else "0",
                RESIDUAL_SPEED.key: _exact(self.residual_speed[i]),
                EXIT_OBLIQUITY.key: _exact(self.exit_obliquity[i], EXIT_OBLIQUITY),
                RADIUS.key: _exact(self.radius[i], RADIUS),
                MASS.key: _exact(self.mass[i], MASS),
                "weight": _exact(self.weight[i]),
                "source": spreadsheet_safe(self.notes[i]),
            }
            writer.writerow([cells[c] for c in header])
        return buffer.getvalue()


def _exact(value: float, declared: Parameter | None = None) -> str:
    """``value`` [SI] in user units, as the shortest text that reads back to it; "" if NaN."""
    value = float(value)
    if math.isnan(value):
        return ""
    if declared is None:
        return repr(value)
    number = declared.user_number(value)
    return repr(number if number is not None else value / declared.scale)


def _take_labels(labels: Sequence[str], kept: np.ndarray) -> Sequence[str]:
    if isinstance(labels, ShotLabels):
        return labels.take(kept)
    return tuple(labels[i] for i in kept)


def _of_rows(columns: ShotColumns, source: str, word: str = "line") -> Shots:
    """Shots in SI units from checked rows in user units."""
    found = columns.arrays()
    return Shots(
        impact_speed=found["impact_speed"],
        impact_obliquity=found["impact_obliquity"] * IMPACT_OBLIQUITY.scale,
        residual_speed=found["residual_speed"],
        exit_obliquity=found["exit_obliquity"] * EXIT_OBLIQUITY.scale,
        outcome=found["outcome"],
        labels=ShotLabels(source, np.array(columns.numbers, dtype=np.int64), word),
        source=source,
        perforated=found["perforated"],
        radius=found["radius"] * RADIUS.scale,
        mass=found["mass"] * MASS.scale,
        weight=found["weight"],
        notes=tuple(columns.notes),
    )
