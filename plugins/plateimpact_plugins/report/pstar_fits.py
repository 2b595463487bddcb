"""P* (and α*) from oblique shots, a and b held fixed: one P* for every shot, or the
report's variable-P* procedure (a ricochet-range and a perforation-range P* at each
obliquity), written as the table the ``variable-pstar`` plug-in reads
(docs/calibration.md, "P* and α* from oblique shots").
"""

from __future__ import annotations

import csv
import io
import math

import attrs
import numpy as np

from plateimpact import (
    CalibrationError,
    ConvergenceError,
    Plate,
    Shots,
    Simulation,
    Sphere,
    calibration,
    limits,
)

from . import fit_views
from .presets import DEFAULT_SPHERE
from .pstar_plan import MAX_FIT_SCENES, check_work, unfittable
from .pstar_search import (
    ALPHA,
    PSTAR,
    Cost,
    LineModel,
    ProbabilityModel,
    PstarEstimate,
    Search,
    ShotLines,
    fit_sets,
    fit_with_alpha,
)
from .pstar_table import TABLE_COLUMNS

SPEED_RESOLUTION = limits.SPEED_RESOLUTION
SPEED_TOLERANCE = limits.SPEED_TOLERANCE
allowed_outcomes = calibration.allowed_outcomes
shot_lines = calibration.shot_lines
check_finder = calibration.check_finder

#: Fewest shots for a fit of P*, and for each range of the by-obliquity fit.
MIN_SHOTS = 5
MIN_RANGE_SHOTS = 3
#: The most obliquities the by-obliquity fit takes: a row every 0.09°, finer than any
#: obliquity is measured; more are measured obliquities that want grouping, and checking
#: each group costs about a millisecond before anything runs.
MAX_OBLIQUITIES = 1_000
#: Fewest residual speeds whose scatter σ_r can be fitted.
MIN_RESIDUALS = 5
#: After the table's own columns (TABLE_COLUMNS), the standard errors, which its reader
#: ignores.
STDERR_COLUMNS = ("ricochet_pstar_stderr_mm", "perforation_pstar_stderr_mm")


@attrs.frozen(eq=False)
class PreparedShots:
    """A shot set ready for a likelihood: its lines (None if no shot is usable), how many
    shots and residual speeds it uses, and a note on residual speeds left out."""

    lines: ShotLines | None
    shots: int
    residuals: int
    note: str = ""


def prepare(shots: Shots, sphere: Sphere, question: str, model: ProbabilityModel) -> PreparedShots:
    """The shots that say something about ``question`` (outcome_model.QUESTIONS), with
    weight > 0, on their lines; residual speeds of perforations for ``outcome`` and
    ``perforation``, unless fewer than MIN_RESIDUALS and σ_r is to be fitted."""
    radius, mass = shots.spheres(sphere)
    perforated = np.asarray(shots.perforated, dtype=bool)
    allowed = allowed_outcomes(shots.outcome, perforated, question)
    use = (allowed != 0) & (shots.weight > 0)
    residual = shots.residual_speed
    recorded = use & perforated & np.isfinite(residual) & (residual > 0) & (question != "ricochet")
    note = ""
    if model.residual_sigma is None and 0 < recorded.sum() < MIN_RESIDUALS:
        count = int(recorded.sum())
        note = (
            f"{count} residual speed{'s' if count > 1 else ''} not used: too few to fit "
            f"their scatter sigma_r (at least {MIN_RESIDUALS}; or give it: --residual-sigma)"
        )
        recorded[:] = False
    if not use.any():
        return PreparedShots(None, 0, 0, note)
    lines = shot_lines(
        shots.impact_speed[use], shots.impact_obliquity[use], radius[use], mass[use],
        allowed[use], np.where(recorded, residual, np.nan)[use], shots.weight[use],
        model.speed_sigma,
    )  # fmt: skip
    return PreparedShots(lines, int(use.sum()), int(recorded.sum()), note)


def _check_model(simulation: Simulation, fit_alpha: bool) -> None:
    reads = simulation.model.plate_constants()
    wanted = [PSTAR] + ([ALPHA] if fit_alpha else [])
    missing = [name for name in wanted if name not in reads]
    if missing:
        failure = simulation.model.failure.name
        raise CalibrationError(
            f"P* fit: the failure model {failure!r} does not read {', '.join(missing)} "
            "(fit with plugging or hinge)"
        )


@attrs.frozen(eq=False)
class PstarFit:
    """P* (and α*) of a plate fitted to shots: ``plate`` carries them, ``estimate`` has
    the standard errors, log-likelihood, σ_r and the model's bands at the maximum."""

    plate: Plate
    estimate: PstarEstimate
    alpha_fitted: bool
    model: ProbabilityModel
    shots: int
    residual_shots: int
    note: str
    cost: Cost

    __repr__ = fit_views.pstar_repr
    _repr_html_ = fit_views.pstar_html

    @property
    def pstar(self) -> float:
        """P* [m]."""
        return self.estimate.pstar

    @property
    def pstar_stderr(self) -> float:
        """Standard error of P* [m]."""
        return self.estimate.pstar_stderr


def fit_pstar(
    shots: Shots,
    plate: Plate,
    *,
    sphere: Sphere = DEFAULT_SPHERE,
    simulation: Simulation | None = None,
    model: ProbabilityModel | None = None,
    fit_alpha: bool = False,
    resolution: float = SPEED_RESOLUTION,
    tolerance: float = SPEED_TOLERANCE,
    max_scenes: int | None = MAX_FIT_SCENES,
) -> PstarFit:
    """P* [m] (and α* [rad] with ``fit_alpha``) by maximum likelihood over every shot
    with weight > 0: recorded outcomes (else perforated or not) and residual speeds.

    ``plate`` gives a, b and α* (the start when fitted); ``resolution`` and
    ``tolerance`` [m/s] are the boundary finder's. Before any scene runs:
    :class:`CalibrationError` when the shots are too few or plainly cannot fix P*
    (:func:`~.pstar_plan.unfittable`), :class:`~plateimpact.base.errors.WorkBoundError` when
    the fit would run more than about ``max_scenes`` scenes (None: no bound). After:
    :class:`CalibrationError` when the likelihood does not fix P*,
    :class:`ConvergenceError` when the search does not converge.
    """
    simulation = simulation or Simulation.from_names()
    model = model or ProbabilityModel()
    _check_model(simulation, fit_alpha)
    check_finder(resolution, tolerance)
    prepared = prepare(shots, sphere, "outcome", model)
    if prepared.lines is None or prepared.shots < MIN_SHOTS:
        raise CalibrationError(
            f"P* fit: {prepared.shots} shots with weight > 0, at least {MIN_SHOTS} needed"
        )
    reason = unfittable(prepared.lines, prepared.shots, MIN_SHOTS)
    if reason is not None:
        raise CalibrationError(f"P* not identified: {reason}")
    check_work("P* fit", [prepared.lines], resolution, fit_alpha, max_scenes)
    lines = LineModel(simulation, sphere, plate, resolution, tolerance)
    search = Search(lines, [prepared.lines], model, plate.failure_angle)
    (estimate,) = fit_sets(search)
    if not estimate.identified:
        raise CalibrationError(f"P* not identified: {estimate.reason}")
    if fit_alpha:
        estimate, converged = fit_with_alpha(search, estimate)
        if not estimate.identified:
            raise CalibrationError(f"P* and alpha* not identified: {estimate.reason}")
        if not converged:
            raise ConvergenceError(
                "P* and alpha* fit (Nelder-Mead) did not converge within its evaluations "
                f"or ended on a bound (P* = {estimate.pstar * 1e3:.4g} mm, alpha* = "
                f"{math.degrees(estimate.alpha):.4g} deg)"
            )
    fitted = plate.with_constants(**{PSTAR: estimate.pstar, ALPHA: estimate.alpha})
    return PstarFit(
        fitted, estimate, fit_alpha, model, prepared.shots, prepared.residuals,
        prepared.note, lines.cost,
    )  # fmt: skip


@attrs.frozen(eq=False)
class PstarRow:
    """One obliquity [rad] of the by-obliquity fit: the ricochet-range and the
    perforation-range estimates (one not identified takes the other's P*, saying so),
    the shots each used, the transition band [m/s] of the table, and notes."""

    obliquity: float
    ricochet: PstarEstimate
    perforation: PstarEstimate
    ricochet_shots: int
    perforation_shots: int
    transition_start: float
    transition_end: float
    notes: tuple[str, ...]


@attrs.frozen(eq=False)
class PstarTableFit:
    """The variable-P* table fitted to shots, one row per impact obliquity, with the
    ``alpha`` α* [rad] it was fitted at."""

    rows: tuple[PstarRow, ...]
    alpha: float
    model: ProbabilityModel
    cost: Cost

    __repr__ = fit_views.table_repr
    _repr_html_ = fit_views.table_html

    def csv_text(self) -> str:
        """The table as the ``variable-pstar`` plug-in reads it, with the standard
        errors [mm] in two more columns (empty where the value was not fitted)."""
        buffer = io.StringIO()
        writer = csv.writer(buffer, lineterminator="\n")
        writer.writerow(TABLE_COLUMNS + STDERR_COLUMNS)
        for row in self.rows:
            writer.writerow(
                [f"{math.degrees(row.obliquity):.10g}"]
                + [f"{e.pstar * 1e3:.6g}" for e in (row.ricochet, row.perforation)]
                + [f"{row.transition_start:.6g}", f"{row.transition_end:.6g}"]
                + [
                    f"{e.pstar_stderr * 1e3:.3g}" if math.isfinite(e.pstar_stderr) else ""
                    for e in (row.ricochet, row.perforation)
                ]
            )
        return buffer.getvalue()


def fit_pstar_by_obliquity(
    shots: Shots,
    plate: Plate,
    *,
    sphere: Sphere = DEFAULT_SPHERE,
    simulation: Simulation | None = None,
    model: ProbabilityModel | None = None,
    resolution: float = SPEED_RESOLUTION,
    tolerance: float = SPEED_TOLERANCE,
    max_scenes: int | None = MAX_FIT_SCENES,
) -> PstarTableFit:
    """At each impact obliquity of ``shots``, the P* that the ricochet-range data want
    (ricochet or not) and the P* that the perforation-range data want (perforated or
    not, and residual speeds): the report's variable-P* procedure. All fits advance in
    the same batches. A range with too few shots, or whose likelihood does not fix P*,
    takes the other range's value (the row's notes say so). Every obliquity is checked
    before any scene runs: those where neither range can fix P* (too few shots, or all
    one outcome: :func:`~.pstar_plan.unfittable`) raise one :class:`CalibrationError`
    naming the first and counting the rest, and a fit over about ``max_scenes`` scenes a
    :class:`~plateimpact.base.errors.WorkBoundError`; an obliquity whose likelihoods turn out
    to fix neither raises :class:`CalibrationError` after the fit, all of them at once."""
    simulation = simulation or Simulation.from_names()
    model = model or ProbabilityModel()
    _check_model(simulation, False)
    check_finder(resolution, tolerance)
    if len(shots) < MIN_SHOTS:
        raise CalibrationError(f"P* fit: {len(shots)} shots, at least {MIN_SHOTS} needed")
    count = np.unique(shots.impact_obliquity).size
    if count > MAX_OBLIQUITIES:
        raise CalibrationError(
            f"P* by obliquity: {shots.source} has shots at {count:,} obliquities, more than "
            f"the {MAX_OBLIQUITIES:,} a table takes (a group is the shots at exactly one "
            "obliquity: round measured obliquities to the nominal ones first)"
        )
    groups = shots.groups_by_obliquity()
    parts: dict[tuple[float, str], PreparedShots] = {}
    fitted: dict[tuple[float, str], PstarEstimate] = {}
    sets, keys, refused = [], [], []
    for obliquity, group in groups.items():
        reasons = []
        for question in ("ricochet", "perforation"):
            prepared = prepare(group, sphere, question, model)
            parts[obliquity, question] = prepared
            reason = unfittable(prepared.lines, prepared.shots, MIN_RANGE_SHOTS)
            if reason is None and prepared.lines is not None:
                sets.append(prepared.lines)
                keys.append((obliquity, question))
            else:
                reasons.append(f"{question} range: {reason}")
                fitted[obliquity, question] = PstarEstimate(
                    math.nan, math.nan, plate.failure_angle, identified=False, reason=str(reason)
                )
        if len(reasons) == 2:
            refused.append((obliquity, "; ".join(reasons)))
    _refuse(refused, "")
    check_work("P* by obliquity", sets, resolution, False, max_scenes)
    lines = LineModel(simulation, sphere, plate, resolution, tolerance)
    if sets:
        search = Search(lines, sets, model, plate.failure_angle)
        fitted.update(zip(keys, fit_sets(search), strict=True))
    rows, refused = [], []
    for obliquity, group in groups.items():
        try:
            rows.append(_row(obliquity, group, parts, fitted))
        except _Unidentified as exc:
            refused.append((obliquity, str(exc)))
    _refuse(refused, " after the fit")
    return PstarTableFit(tuple(rows), plate.failure_angle, model, lines.cost)


class _Unidentified(Exception):
    """An obliquity where neither range's likelihood fixes P*."""


def _refuse(refused: list[tuple[float, str]], when: str) -> None:
    """One :class:`CalibrationError` line for every obliquity that cannot be fitted: the
    first in full, then how many more and where."""
    if not refused:
        return
    (first, why), rest = refused[0], refused[1:]
    more = ""
    if rest:
        shown = ", ".join(f"{math.degrees(o):g}" for o, _ in rest[:10])
        more = (
            f" (and {len(rest)} more obliquities: {shown}{', ...' if len(rest) > 10 else ''} deg)"
        )
    raise CalibrationError(f"P* not identified{when} at {math.degrees(first):g} deg: {why}{more}")


def _row(
    obliquity: float,
    group: Shots,
    parts: dict[tuple[float, str], PreparedShots],
    fitted: dict[tuple[float, str], PstarEstimate],
) -> PstarRow:
    ricochet, perforation = fitted[obliquity, "ricochet"], fitted[obliquity, "perforation"]
    if not (ricochet.identified or perforation.identified):
        raise _Unidentified(
            f"ricochet range: {ricochet.reason}; perforation range: {perforation.reason}"
        )
    notes = [parts[obliquity, q].note for q in ("ricochet", "perforation")]
    if not ricochet.identified:
        notes.append(f"ricochet range: {ricochet.reason}; the perforation-range P* is used")
        ricochet = attrs.evolve(perforation, pstar_stderr=math.nan, identified=False,
                                reason=ricochet.reason)  # fmt: skip
    if not perforation.identified:
        notes.append(f"perforation range: {perforation.reason}; the ricochet-range P* is used")
        perforation = attrs.evolve(ricochet, pstar_stderr=math.nan, identified=False,
                                   reason=perforation.reason)  # fmt: skip
    start, end, note = _transition(group, ricochet, perforation)
    return PstarRow(
        obliquity, ricochet, perforation, parts[obliquity, "ricochet"].shots,
        parts[obliquity, "perforation"].shots, start, end,
        tuple(n for n in [*notes, note] if n),
    )  # fmt: skip


def _transition(
    group: Shots, ricochet: PstarEstimate, perforation: PstarEstimate
) -> tuple[float, float, str]:
    """The table's band [m/s]: from the last ricochet with the ricochet-range P* to the
    first perforation with the perforation-range P* (docs/variable-pstar.md), on the
    group's first line (its smallest sphere); when one is missing both are the other,
    when both are, the median shot speed; when they cross, both their mean."""
    start = ricochet.bands[0].ricochet_limit
    end = perforation.bands[0].ballistic_limit
    end = end if math.isfinite(end) else math.nan
    if math.isnan(start) and math.isnan(end):
        middle = float(np.median(group.impact_speed))
        return middle, middle, "no ricochet or ballistic limit near the shots: band at their median"
    if math.isnan(start) or math.isnan(end):
        edge = end if math.isnan(start) else start
        return edge, edge, ""
    if start > end:
        middle = 0.5 * (start + end)
        note = (
            f"the ricochet limit ({start:.1f} m/s) is above the ballistic limit "
            f"({end:.1f} m/s): band collapsed to their mean"
        )
        return middle, middle, note
    return start, end, ""
