"""How V50 estimates show in a notebook: a short text (``__repr__``) and a small HTML table
(``_repr_html_``) of a probit or logit fit and of a MIL-STD-662F V50, speeds in m/s, as
``plateimpact v50`` prints them.

The estimates are read through their attributes, so that this module, below the
classes that use it, imports none of them.
"""

from __future__ import annotations

from typing import Any

from ..base.display import (
    SPEED,
    cell,
    heading,
    html_block,
    html_fields,
    html_table,
    quantity,
    short_repr,
)
from .likelihood import shown
from .profile import Interval

#: The quantities of a fit, by name: the attribute stem and how a table heads it.
QUANTITIES = (("v50", "V50"), ("sigma", "sigma"), ("v10", "V10"), ("v90", "V90"))


def interval(found: Interval | None) -> str:
    """``[305.1, 320.4]``, an end the data do not bound as ``unbounded``."""
    if found is None:
        return "-"
    low, high = ("unbounded" if x is None else cell(SPEED, x, 4) for x in found)
    return f"[{low}, {high}]"


def _counts(fit: Any) -> str:
    rows = f" ({fit.rows} rows)" if fit.rows != fit.rounds else ""
    return f"{shown(fit.rounds)} shots{rows}, {shown(fit.perforations)} perforated"


def fit_repr(fit: Any) -> str:
    level = f"{100 * fit.confidence:g}%"
    parts = [
        f"{fit.method}",
        *(
            f"{name} {quantity(SPEED, getattr(fit, f'{key}_m_s'), 4)} "
            f"{interval(getattr(fit, f'{key}_ci_m_s'))}"
            for key, name in QUANTITIES[:2]
        ),
        f"{level} profile-likelihood intervals",
        _counts(fit),
    ]
    return short_repr("V50Fit", parts)


def fit_html(fit: Any) -> str:
    boot = fit.bootstrap_resamples > 0
    level = f"{100 * fit.confidence:g}%"
    header = ["", heading("estimate", SPEED), f"{level} profile likelihood [m/s]"]
    header += [f"{level} bootstrap [m/s]"] if boot else []
    rows = []
    for key, name in QUANTITIES:
        row = [
            name,
            cell(SPEED, getattr(fit, f"{key}_m_s"), 5),
            interval(getattr(fit, f"{key}_ci_m_s")),
        ]
        if boot:
            row.append(interval(getattr(fit, f"{key}_bootstrap_ci_m_s")))
        rows.append(row)
    low, high = fit.mixed_zone_m_s
    fields: list[tuple[str, object]] = [
        ("shots", _counts(fit)),
        (heading("zone of mixed results", SPEED), f"{cell(SPEED, low)} to {cell(SPEED, high)}"),
        ("log-likelihood", f"{fit.log_likelihood:.6g}"),
    ]
    if boot:
        fields.append((
            "bootstrap resamples",
            f"{fit.bootstrap_resamples:,}: {fit.bootstrap_separated} separated, "
            f"{fit.bootstrap_flat} flat, {fit.bootstrap_failed} failed (left out)",
        ))  # fmt: skip
    return html_block(f"V50Fit: {fit.method}", html_table(header, rows), html_fields(fields))


def mil_std_repr(found: Any) -> str:
    parts = [
        f"V50 {quantity(SPEED, found.v50_m_s, 4)} from {found.rounds} of {found.shots} rounds",
        f"spanning {quantity(SPEED, found.spread_m_s, 3)} "
        f"(at most {quantity(SPEED, found.spread_allowed_m_s, 3)})",
        f"highest partial {', '.join(cell(SPEED, v) for v in found.partial_speeds_m_s)} m/s",
        f"lowest complete {', '.join(cell(SPEED, v) for v in found.complete_speeds_m_s)} m/s",
    ]
    return short_repr("MilStd662F", parts)


def mil_std_html(found: Any) -> str:
    fields: list[tuple[str, object]] = [
        (heading("V50", SPEED), cell(SPEED, found.v50_m_s, 5)),
        ("rounds averaged", f"{found.rounds} of {found.shots}"),
        (heading("span", SPEED), cell(SPEED, found.spread_m_s, 4)),
        (heading("span allowed", SPEED), cell(SPEED, found.spread_allowed_m_s, 4)),
        (heading("highest partial penetrations", SPEED),
         ", ".join(cell(SPEED, v) for v in found.partial_speeds_m_s)),
        (heading("lowest complete penetrations", SPEED),
         ", ".join(cell(SPEED, v) for v in found.complete_speeds_m_s)),
    ]  # fmt: skip
    return html_block("MilStd662F", html_fields(fields))
