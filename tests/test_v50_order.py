"""V50 fits that never refuse valid data: the fit from any row order is statsmodels'
binomial GLM fit of the same rows (an independent solver: IRLS, frequency weights); the
bootstrap refits what a solver once failed on rather than counting it flat; weights
count as rounds. The data sets main@86344fb refused depending on the row order are in
tests/data (with how they were found); benchmarks/v50_refusals.py measures before/after.
"""

from __future__ import annotations

import math
import warnings
from pathlib import Path

import numpy as np
import pytest
import statsmodels.api as sm
from scipy import stats

from plateimpact.base.errors import V50Error
from plateimpact.storage.shots import Shots
from plateimpact.v50 import METHODS, fit_v50
from plateimpact.v50 import solver as solver_module
from plateimpact.v50.bootstrap import bootstrap_intervals
from plateimpact.v50.fit import LEVELS
from plateimpact.v50.likelihood import LINKS, check_shots, prepared
from plateimpact.v50.solver import maximum

DATA = Path(__file__).resolve().parent / "data"
#: Agreement with the GLM [relative, V50 and σ]: both solvers go to their maxima's
#: rounding (a gradient of 1e-15); this leaves room for the GLM's conditioning (raw speeds).
TOLERANCE = 1e-8


def from_file(name: str) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    shots = Shots.from_csv(DATA / name)
    return shots.impact_speed, shots.perforated, shots.weight


def glm(speed, perforated, weight, method, start=None):
    """(V50, σ) [m/s] and (β0, β1) from statsmodels' binomial GLM with a probit or logit
    link and frequency weights, on the raw speeds: P = F(β0 + β1 v), V50 = −β0/β1, scale
    1/β1 (σ = scale for probit, scale π/√3 for logit)."""
    link = sm.families.links.Probit() if method == "probit" else sm.families.links.Logit()
    model = sm.GLM(np.asarray(perforated, dtype=float), sm.add_constant(speed),
                   family=sm.families.Binomial(link=link), freq_weights=weight)  # fmt: skip
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")  # statsmodels' notes on a perfect fit and the like
        found = model.fit(tol=1e-13, tol_criterion="params", maxiter=200, start_params=start)
    intercept, slope = found.params
    per_scale = 1.0 if method == "probit" else math.pi / math.sqrt(3.0)
    return (-intercept / slope, per_scale / slope), found.params


def random_sets(count: int = 24):
    """Seeded go/no-go sets of 8–40 rows from probit curves: unit weights, whole weights
    1–6 and fractional weights 0.25–3, a third each; only sets a fit takes (a zone of
    mixed results, perforation more likely with speed by the GLM)."""
    rng = np.random.default_rng(20240611)
    found = []
    while len(found) < count:
        rows = int(rng.integers(8, 41))
        v50, sigma = rng.uniform(300.0, 900.0), rng.uniform(5.0, 80.0)
        speed = rng.uniform(v50 - 2.5 * sigma, v50 + 2.5 * sigma, rows)
        perforated = rng.random(rows) < stats.norm.cdf((speed - v50) / sigma)
        weight = [np.ones(rows), rng.integers(1, 7, rows).astype(float),
                  rng.uniform(0.25, 3.0, rows)][len(found) % 3]  # fmt: skip
        try:
            check_shots(speed, perforated, weight, "set")
        except V50Error:
            continue
        if glm(speed, perforated, weight, "probit")[1][1] > 0:
            found.append((speed, perforated, weight))
    return found


@pytest.fixture(scope="module")
def sets():
    """The two files main refused, then the random sets."""
    files = [from_file("v50_weighted_13_rows.csv"), from_file("v50_unweighted_30_shots.csv")]
    return files + random_sets()


def solved(speed, perforated, weight, method):
    """(V50, σ) [m/s] by plateimpact's solver on the rows in the order given (fit_v50
    puts them in one order first; this does not)."""
    shots = prepared(speed, perforated, weight)
    link = LINKS[method]
    best = maximum(shots, link, "shots")
    return shots.speed(best.location), shots.spread * best.scale * link.sigma_per_scale


@pytest.mark.parametrize("method", METHODS)
def test_the_solver_finds_the_glm_fit_from_every_row_order(sets, method):
    """Each set in 12 seeded row orders (the 13-row file in 100: main refused a quarter
    of them), solved on the rows as ordered: V50 and σ within 1e-8 of the GLM's."""
    rng = np.random.default_rng(7)
    for k, (speed, perforated, weight) in enumerate(sets):
        expected = glm(speed, perforated, weight, method)[0]
        for _ in range(100 if k == 0 else 12):
            order = rng.permutation(speed.size)
            found = solved(speed[order], perforated[order], weight[order], method)
            np.testing.assert_allclose(found, expected, rtol=TOLERANCE, err_msg=f"set {k}")


@pytest.mark.parametrize("method", METHODS)
@pytest.mark.parametrize("name", ["v50_weighted_13_rows.csv", "v50_unweighted_30_shots.csv"])
def test_fit_v50_gives_one_answer_whatever_the_row_order(name, method):
    """The files main refused (probit) in the file's order and in others: every order is
    fitted, to the GLM's V50 and σ, and gives the same fit, bootstrap intervals too."""
    speed, perforated, weight = from_file(name)
    expected = glm(speed, perforated, weight, method)[0]
    first = fit_v50(speed, perforated, weight, method=method, bootstrap=20).to_json()
    np.testing.assert_allclose([first["v50_m_s"], first["sigma_m_s"]], expected, rtol=TOLERANCE)
    rng = np.random.default_rng(3)
    for _ in range(12):
        order = rng.permutation(speed.size)
        fit = fit_v50(speed[order], perforated[order], weight[order], method=method, bootstrap=20)
        assert fit.to_json() == first


def test_the_bootstrap_refits_resamples_a_solver_failed_on_rather_than_counting_them_flat():
    """The 13-row file's probit bootstrap, 200 resamples at seed 11 (two of which main's
    solver did not converge on, and counted flat, σ = ∞), drawn from the GLM's curve:
    each resample refitted here by the GLM, separated ones read as σ = 0 and those with
    no rise as flat (σ = ∞), as plateimpact.v50.bootstrap documents. The σ interval is the
    5th and 195th of the 200 σ sorted, ((1 ∓ 0.95)/2 × 200); the counts agree."""
    speed, perforated, weight = from_file("v50_weighted_13_rows.csv")
    (v50, sigma), params = glm(speed, perforated, weight, "probit")
    resamples, seed = 200, 11
    found = bootstrap_intervals(speed, perforated, weight, LINKS["probit"], (v50, sigma),
                                resamples, seed, 0.95, LEVELS)  # fmt: skip
    # The draws, as documented: per row a binomial count of perforations among its rounds.
    p = stats.norm.cdf((speed - v50) / sigma)
    goes = np.random.default_rng(seed).binomial(weight.astype(np.int64), p, (resamples, speed.size))
    sigmas, flat, separated = [], 0, 0
    for count in goes:
        rows_v = np.concatenate([speed, speed])
        rows_y = np.repeat([True, False], speed.size)
        rows_w = np.concatenate([count, weight - count]).astype(float)
        go, no_go = rows_y & (rows_w > 0), ~rows_y & (rows_w > 0)
        if rows_v[no_go].max() <= rows_v[go].min():
            sigmas.append(0.0)
            separated += 1
            continue
        if rows_v[go].max() > rows_v[no_go].min():
            (_, resampled), beta = glm(rows_v, rows_y, rows_w, "probit", start=params)
            if beta[1] > 0:
                sigmas.append(resampled)
                continue
        sigmas.append(math.inf)
        flat += 1
    ordered = np.sort(sigmas)
    low, high = found.intervals["sigma"]
    assert (found.separated, found.flat) == (separated, flat)
    assert high == pytest.approx(ordered[194], rel=1e-7)
    assert low == pytest.approx(ordered[4], rel=1e-7)  # main took the 6th
    assert found.failed == 0


def test_a_resample_no_solver_fits_is_left_out_and_counted(monkeypatch):
    """With every resample's fit made to fail, none is read as flat: all are counted
    failed, and σ gets no interval (more left out than a tail holds)."""
    speed, perforated, weight = from_file("v50_weighted_13_rows.csv")

    def fails(shots, link, label):
        raise V50Error(f"{label}: the {link.name} fit did not converge: injected")

    monkeypatch.setattr("plateimpact.v50.bootstrap.maximum", fails)
    fit = fit_v50(speed, perforated, weight, bootstrap=50)
    assert fit.bootstrap_failed == 50 - fit.bootstrap_separated - fit.bootstrap_flat
    assert fit.bootstrap_failed > 40
    assert fit.sigma_bootstrap_ci_m_s is None and fit.v50_bootstrap_ci_m_s is None


def test_the_fallback_solver_takes_over_where_newton_stops_short(monkeypatch):
    """Newton's method made to return its start (the flat curve, not a maximum): the
    trust-region fallback reaches the GLM's fit; with both made to stop there, the fit
    is refused in one line."""
    speed, perforated, weight = from_file("v50_weighted_13_rows.csv")
    expected = glm(speed, perforated, weight, "probit")[0]
    monkeypatch.setattr(solver_module, "newton", lambda problem, start: (start, 0))
    fit = fit_v50(speed, perforated, weight, bootstrap=0)
    np.testing.assert_allclose([fit.v50_m_s, fit.sigma_m_s], expected, rtol=TOLERANCE)
    monkeypatch.setattr(solver_module, "_trust_region", lambda problem, start, tol: (start, 0))
    with pytest.raises(V50Error, match="the probit fit did not converge") as caught:
        fit_v50(speed, perforated, weight, bootstrap=0, label="s.csv at 0 deg")
    assert "\n" not in str(caught.value) and str(caught.value).startswith("s.csv at 0 deg: ")


def test_shots_are_counted_as_rounds_and_rows():
    """53 rounds in 13 rows: shots and rounds 53, rows 13, perforations the perforating
    rounds; the same shots one row each give the same fit with rows = rounds = 53."""
    speed, perforated, weight = from_file("v50_weighted_13_rows.csv")
    fit = fit_v50(speed, perforated, weight, bootstrap=0)
    assert (fit.shots, fit.rounds, fit.rows) == (53, 53, 13)
    assert fit.perforations == int(weight[perforated].sum()) == 25
    repeats = weight.astype(int)
    expanded = fit_v50(np.repeat(speed, repeats), np.repeat(perforated, repeats), bootstrap=0)
    assert (expanded.shots, expanded.rounds, expanded.rows, expanded.perforations) == (
        53, 53, 53, 25
    )  # fmt: skip
    assert expanded.v50_m_s == pytest.approx(fit.v50_m_s, rel=1e-12)
    fractional = fit_v50(speed, perforated, weight / 4, bootstrap=0)
    assert (fractional.rounds, fractional.rows) == (13.25, 13)


def test_three_weighted_rows_that_overlap_both_ways_are_fitted():
    """Three rows, 11 rounds: a perforation at 480 m/s below 5 non-perforations at 500
    m/s, below 5 perforations at 520 m/s. The outcomes overlap both ways, so the
    likelihood has a maximum: fitted (the GLM's), where main refused "3 shots" (rows)."""
    speed, perforated, weight = [480.0, 500.0, 520.0], [True, False, True], [1.0, 5.0, 5.0]
    for method in METHODS:
        fit = fit_v50(speed, perforated, weight, method=method, bootstrap=0)
        expected = glm(np.array(speed), np.array(perforated), np.array(weight), method)[0]
        np.testing.assert_allclose([fit.v50_m_s, fit.sigma_m_s], expected, rtol=TOLERANCE)
        assert (fit.rounds, fit.rows) == (11, 3)


@pytest.mark.parametrize(
    ("speed", "perforated", "weight", "words"),
    [
        ([480.0, 500.0, 520.0], [0, 1, 0], [1.0, 1.0, 1.0], "too few shots for a V50 fit: 3 shots"),
        ([480.0, 500.0, 520.0, 540.0], [0, 1, 0, 1], [0.5] * 4, r"2 shots \(in 4 rows\)"),
        ([480.0, 490.0, 510.0, 520.0], [1, 1, 0, 0], [2.0] * 4, "show no ballistic limit"),
        ([480.0, 500.0, 500.0, 520.0], [1, 1, 0, 0], [1.0] * 4, "show no ballistic limit"),
    ],
)
def test_too_few_rounds_and_falling_separation_are_refused_in_one_line(
    speed, perforated, weight, words
):
    """Too few rounds (weights counted), and perforations all at or below the
    non-perforations (the likelihood's maximum is a falling step: no ballistic limit)."""
    with pytest.raises(V50Error, match=words) as caught:
        fit_v50(speed, perforated, weight, label="s.csv at 0 deg")
    assert "\n" not in str(caught.value) and str(caught.value).startswith("s.csv at 0 deg: ")
