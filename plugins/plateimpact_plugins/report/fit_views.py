"""How the calibration's results show in a notebook: a short text (``__repr__``) and a
small HTML table (``_repr_html_``) of a fit of a and b, of both fits with the shots' DRI
fit, of P* (and α*), and of the variable-P* table, each constant in the unit its
declaration gives (a [N/m²], b [kg/m³], P* [mm], α* [deg]), speeds in m/s.

Each function takes the result as ``self``: the classes assign them as their methods.
"""

from __future__ import annotations

import math
from typing import Any

from plateimpact import display

from .constants import CRITICAL_PENETRATION, DENSITY_B, FAILURE_ANGLE, STRENGTH_A

SPEED = display.SPEED
_ESTIMATE = ["", "estimate", "standard error"]


def _plus_minus(declared: Any, value: float, stderr: float) -> str:
    """``4.61 +/- 0.08 mm``: an estimate [SI] with its standard error, in the user's unit."""
    return (
        f"{display.cell(declared, value, 5)} +/- {display.cell(declared, stderr, 2)} "
        f"{display.unit(declared)}"
    ).rstrip()


def _row(declared: Any, name: str, value: float, stderr: float) -> list[object]:
    heading = display.heading(name, declared)
    return [heading, display.cell(declared, value, 5), display.cell(declared, stderr, 2)]


def _state(fit: Any) -> str:
    done = "converged" if fit.converged else "did not converge"
    return f"{done} in {fit.iterations} iterations"


def calibration_repr(self: Any) -> str:
    parts = [
        self.method,
        f"a {_plus_minus(STRENGTH_A, self.a, self.a_stderr)}",
        f"b {_plus_minus(DENSITY_B, self.b, self.b_stderr)}",
        f"correlation {self.correlation:.3g}",
        _state(self),
        f"rms residual {display.quantity(SPEED, self.rms_residual, 3)}",
    ]
    return display.short_repr("Calibration", parts)


def _calibration_fields(fit: Any) -> list[tuple[str, object]]:
    model = fit.model_fit
    return [
        ("correlation of a and b", f"{fit.correlation:.3g}"),
        ("iterations", _state(fit)),
        ("model's DRI fit", f"R {model.R:.5g}, V0 {display.quantity(SPEED, model.V0, 5)}"),
        ("largest relative difference from the shots' R, V0", f"{fit.dri_mismatch:.2g}"),
        (display.heading("rms residual", SPEED), display.cell(SPEED, fit.rms_residual, 3)),
    ]


def calibration_html(self: Any) -> str:
    rows = [
        _row(STRENGTH_A, "a", self.a, self.a_stderr),
        _row(DENSITY_B, "b", self.b, self.b_stderr),
    ]
    tables = display.html_table(_ESTIMATE, rows), display.html_fields(_calibration_fields(self))
    return display.html_block(f"Calibration: {self.method}", *tables)


def report_repr(self: Any) -> str:
    dri = self.dri
    parts = [
        f"{len(self.shots):,} shots",
        f"DRI R {dri.R:.5g}, V0 {display.quantity(SPEED, dri.V0, 5)}",
        *(
            f"{fit.method} a {display.quantity(STRENGTH_A, fit.a, 5)}, "
            f"b {display.quantity(DENSITY_B, fit.b, 5)}"
            for fit in (self.newton, self.direct)
        ),
    ]
    return display.short_repr("CalibrationReport", parts)


def report_html(self: Any) -> str:
    header = ["method", display.heading("a", STRENGTH_A), display.heading("+/-", STRENGTH_A),
              display.heading("b", DENSITY_B), display.heading("+/-", DENSITY_B),
              "iterations", display.heading("rms residual", SPEED)]  # fmt: skip
    rows = [
        [fit.method, display.cell(STRENGTH_A, fit.a, 5), display.cell(STRENGTH_A, fit.a_stderr, 2),
         display.cell(DENSITY_B, fit.b, 5), display.cell(DENSITY_B, fit.b_stderr, 2),
         _state(fit), display.cell(SPEED, fit.rms_residual, 3)]
        for fit in (self.newton, self.direct)
    ]  # fmt: skip
    title = f"CalibrationReport: a and b from {len(self.shots):,} shots ({self.shots.source})"
    tables = [display.html_table(header, rows, caption="a and b"), self.dri._repr_html_()]
    return display.html_block(title, *tables)


def _alpha(fit: Any) -> str:
    estimate = fit.estimate
    if fit.alpha_fitted:
        return f"alpha* {_plus_minus(FAILURE_ANGLE, estimate.alpha, estimate.alpha_stderr)}"
    return f"alpha* {display.quantity(FAILURE_ANGLE, estimate.alpha)} (held)"


def pstar_repr(self: Any) -> str:
    estimate = self.estimate
    parts = [
        f"P* {_plus_minus(CRITICAL_PENETRATION, estimate.pstar, estimate.pstar_stderr)}",
        _alpha(self),
        f"{self.shots:,} shots, {self.residual_shots:,} residual speeds",
        f"log-likelihood {estimate.log_likelihood:.6g}",
    ]
    return display.short_repr("PstarFit", parts)


def pstar_html(self: Any) -> str:
    estimate = self.estimate
    rows = [_row(CRITICAL_PENETRATION, "P*", estimate.pstar, estimate.pstar_stderr)]
    if self.alpha_fitted:
        rows.append(_row(FAILURE_ANGLE, "alpha*", estimate.alpha, estimate.alpha_stderr))
    else:
        rows.append([display.heading("alpha* (held)", FAILURE_ANGLE),
                     display.cell(FAILURE_ANGLE, estimate.alpha), "-"])  # fmt: skip
    fields: list[tuple[str, object]] = [
        ("shots", f"{self.shots:,}, of which {self.residual_shots:,} residual speeds"),
        ("log-likelihood", f"{estimate.log_likelihood:.6g}"),
        (display.heading("residual-speed scatter sigma_r", SPEED),
         display.cell(SPEED, estimate.residual_sigma, 3)),
    ]  # fmt: skip
    if self.note:
        fields.append(("note", self.note))
    tables = display.html_table(_ESTIMATE, rows), display.html_fields(fields)
    return display.html_block("PstarFit", *tables)


def table_repr(self: Any) -> str:
    obliquities = [row.obliquity for row in self.rows]
    ranges = [
        f"{what}-range P* "
        + display.spread(CRITICAL_PENETRATION, [getattr(r, what).pstar for r in self.rows])
        for what in ("ricochet", "perforation")
    ]
    parts = [
        f"{len(self.rows)} obliquities {display.spread(display.ANGLE, obliquities)}",
        *ranges,
        f"alpha* {display.quantity(FAILURE_ANGLE, self.alpha)}",
    ]
    return display.short_repr("PstarTableFit", parts)


def _pstar_cells(estimate: Any) -> list[object]:
    stderr = estimate.pstar_stderr
    shown = display.cell(CRITICAL_PENETRATION, stderr, 2) if math.isfinite(stderr) else "-"
    return [display.cell(CRITICAL_PENETRATION, estimate.pstar, 5), shown]


def _transition(row: Any) -> str:
    start, end = (display.cell(SPEED, x) for x in (row.transition_start, row.transition_end))
    return f"{start} to {end}"


def table_html(self: Any) -> str:
    mm = display.unit(CRITICAL_PENETRATION)
    header = [display.heading("impact obliquity", display.ANGLE),
              f"ricochet-range P* [{mm}]", f"+/- [{mm}]", "shots",
              f"perforation-range P* [{mm}]", f"+/- [{mm}]", "shots",
              display.heading("transition", SPEED), "notes"]  # fmt: skip
    rows = [
        [display.cell(display.ANGLE, row.obliquity), *_pstar_cells(row.ricochet),
         f"{row.ricochet_shots:,}", *_pstar_cells(row.perforation),
         f"{row.perforation_shots:,}", _transition(row), "; ".join(row.notes)]
        for row in self.rows
    ]  # fmt: skip
    title = f"PstarTableFit: alpha* {display.quantity(FAILURE_ANGLE, self.alpha)}"
    return display.html_block(title, display.html_table(header, rows))
