"""V50 statistics (plateimpact.v50): maximum-likelihood probit and logit fits against
closed forms and an independent optimiser, profile intervals against their definition,
their coverage on shots drawn from a known curve, the MIL-STD-662F estimate on a
hand-worked example, and the refusals."""

from __future__ import annotations

import math

import numpy as np
import pytest
from scipy import optimize, special, stats

from plateimpact.base.errors import ParameterError, V50Error
from plateimpact.v50 import fit_v50, mil_std_662f

TRUE_V50, TRUE_SIGMA = 500.0, 20.0  # [m/s]


def probit_shots(rng: np.random.Generator, count: int) -> tuple[np.ndarray, np.ndarray]:
    """Shots at speeds uniform in V50 ± 2.5 σ, perforating with probability Φ((v − V50)/σ)."""
    speed = rng.uniform(TRUE_V50 - 2.5 * TRUE_SIGMA, TRUE_V50 + 2.5 * TRUE_SIGMA, count)
    return speed, rng.random(count) < stats.norm.cdf((speed - TRUE_V50) / TRUE_SIGMA)


def negative_log_likelihood(v50, sigma, speed, perforated, weight, method):
    """−log L written out from the model's definition (docs/experiment.md)."""
    scale = sigma if method == "probit" else sigma * math.sqrt(3) / math.pi
    z = (speed - v50) / scale
    cdf = stats.norm.cdf if method == "probit" else special.expit
    p = np.clip(cdf(z), 1e-300, 1 - 1e-16)
    return -np.sum(weight * np.where(perforated, np.log(p), np.log1p(-p)))


#: Two speeds, 10 shots each: 3 of 10 perforate at 480 m/s, 8 of 10 at 520 m/s.
TWO_LEVELS = {
    "speed": np.array([480.0, 480.0, 520.0, 520.0]),
    "perforated": np.array([True, False, True, False]),
    "weight": np.array([3.0, 7.0, 8.0, 2.0]),
}


@pytest.mark.parametrize("method", ["probit", "logit"])
def test_two_speeds_fit_their_observed_shares_exactly(method):
    """With shots at two speeds the two-parameter curve can pass through both observed
    shares, so the maximum-likelihood curve does: F((480 − V50)/s) = 0.3 and
    F((520 − V50)/s) = 0.8, whence s = 40/(F⁻¹(0.8) − F⁻¹(0.3)), V50 = 480 − s F⁻¹(0.3),
    and V10 = V50 + s F⁻¹(0.1) (for logit σ = s π/√3)."""
    quantile = stats.norm.ppf if method == "probit" else special.logit
    scale = 40.0 / (quantile(0.8) - quantile(0.3))
    v50 = 480.0 - scale * quantile(0.3)
    fit = fit_v50(**TWO_LEVELS, method=method, bootstrap=0)
    assert fit.v50_m_s == pytest.approx(v50, abs=1e-5)
    assert fit.scale_m_s == pytest.approx(scale, rel=1e-6)
    sigma = scale if method == "probit" else scale * math.pi / math.sqrt(3)
    assert fit.sigma_m_s == pytest.approx(sigma, rel=1e-6)
    assert fit.v10_m_s == pytest.approx(v50 + scale * quantile(0.1), abs=1e-5)
    assert fit.v90_m_s == pytest.approx(v50 + scale * quantile(0.9), abs=1e-5)
    np.testing.assert_allclose(fit.probability([480.0, 520.0]), [0.3, 0.8], rtol=1e-6)
    # shots are rounds, 3 + 7 + 8 + 2, of which 3 + 8 perforated (main counted rows: 4, 2)
    assert (fit.shots, fit.perforations, fit.rows) == (20, 11, 4)


def test_a_weight_is_that_many_identical_shots():
    expanded = fit_v50(
        np.repeat(TWO_LEVELS["speed"], TWO_LEVELS["weight"].astype(int)),
        np.repeat(TWO_LEVELS["perforated"], TWO_LEVELS["weight"].astype(int)),
        bootstrap=0,
    )
    weighted = fit_v50(**TWO_LEVELS, bootstrap=0)
    for name in ("v50_m_s", "sigma_m_s", "log_likelihood"):
        assert getattr(weighted, name) == pytest.approx(getattr(expanded, name), rel=1e-9)
    for name in ("v50_ci_m_s", "sigma_ci_m_s", "v90_ci_m_s"):
        np.testing.assert_allclose(getattr(weighted, name), getattr(expanded, name), rtol=1e-7)


@pytest.mark.parametrize("method", ["probit", "logit"])
def test_the_fit_is_the_maximum_an_independent_optimiser_finds(method):
    """Nelder–Mead on the written-out −log L over (V50, log σ), with weights."""
    rng = np.random.default_rng(11)
    speed, perforated = probit_shots(rng, 40)
    weight = rng.integers(1, 4, speed.size).astype(float)
    found = optimize.minimize(
        lambda p: negative_log_likelihood(p[0], math.exp(p[1]), speed, perforated, weight, method),
        [480.0, math.log(30.0)],
        method="Nelder-Mead",
        options={"xatol": 1e-9, "fatol": 1e-12, "maxiter": 20_000},
    )
    fit = fit_v50(speed, perforated, weight, method=method, bootstrap=0)
    assert fit.v50_m_s == pytest.approx(found.x[0], abs=1e-4)
    assert fit.sigma_m_s == pytest.approx(math.exp(found.x[1]), rel=1e-5)
    assert fit.log_likelihood == pytest.approx(-found.fun, abs=1e-8)


@pytest.mark.parametrize("method", ["probit", "logit"])
def test_each_profile_interval_end_is_where_the_deviance_reaches_the_chi_square_quantile(method):
    """At each end of the 95 % interval of V50 (σ), −log L minimised over σ (V50) by a
    bounded scalar search written here is the maximum's plus χ²₁(0.95)/2 = 1.9207."""
    rng = np.random.default_rng(4)
    speed, perforated = probit_shots(rng, 30)
    weight = np.ones(speed.size)
    fit = fit_v50(speed, perforated, method=method, bootstrap=0)
    best = -fit.log_likelihood
    for end in fit.v50_ci_m_s:
        profile = optimize.minimize_scalar(
            lambda ls, v50=end: negative_log_likelihood(
                v50, math.exp(ls), speed, perforated, weight, method
            ),
            bounds=(math.log(0.1), math.log(1e4)),
            method="bounded",
            options={"xatol": 1e-10},
        )
        assert 2 * (profile.fun - best) == pytest.approx(stats.chi2.ppf(0.95, 1), abs=1e-5)
    for end in fit.sigma_ci_m_s:
        profile = optimize.minimize_scalar(
            lambda v50, sigma=end: negative_log_likelihood(
                v50, sigma, speed, perforated, weight, method
            ),
            bounds=(300.0, 700.0),
            method="bounded",
            options={"xatol": 1e-10},
        )
        assert 2 * (profile.fun - best) == pytest.approx(stats.chi2.ppf(0.95, 1), abs=1e-5)
    low, high = fit.v10_ci_m_s
    assert low < fit.v10_m_s < high
    low, high = fit.v90_ci_m_s
    assert low < fit.v90_m_s < high


def _holds(interval, truth):
    low, high = interval
    return (low is None or low <= truth) and (high is None or truth <= high)


def test_profile_intervals_hold_the_true_v50_and_sigma_as_often_as_they_say():
    """40 seeded sets of 30 shots from a known probit curve (a refused set counts as a
    miss): the 95 % intervals hold the truth in at least 32 (80 %), and the 50 %
    intervals in 12 to 28: an interval too narrow fails the first, one too wide the
    second. (benchmarks/v50_coverage.py measures 100 repetitions, with the bootstrap.)"""
    rng = np.random.default_rng(2024)
    held = {0.95: [0, 0], 0.5: [0, 0]}
    for _ in range(40):
        speed, perforated = probit_shots(rng, 30)
        for confidence, counts in held.items():
            try:
                fit = fit_v50(speed, perforated, confidence=confidence, bootstrap=0)
            except V50Error:
                continue
            counts[0] += _holds(fit.v50_ci_m_s, TRUE_V50)
            counts[1] += _holds(fit.sigma_ci_m_s, TRUE_SIGMA)
    assert min(held[0.95]) >= 32, held
    assert all(12 <= count <= 28 for count in held[0.5]), held


def test_the_bootstrap_agrees_with_the_profile_on_many_shots():
    """On 300 shots both intervals approach estimate ± 1.96 standard errors: their ends
    agree to a fifth of the width; the same seed gives the same resamples."""
    speed, perforated = probit_shots(np.random.default_rng(8), 300)
    fit = fit_v50(speed, perforated, bootstrap=400, rng=3)
    for name in ("v50", "sigma", "v10", "v90"):
        profile = np.array(getattr(fit, f"{name}_ci_m_s"))
        resampled = np.array(getattr(fit, f"{name}_bootstrap_ci_m_s"))
        width = profile[1] - profile[0]
        np.testing.assert_allclose(resampled, profile, atol=0.2 * width, err_msg=name)
    # The draws are the seed's whatever their number: fifty show it as well as 400.
    few = fit_v50(speed, perforated, bootstrap=50, rng=3)
    again = fit_v50(speed, perforated, bootstrap=50, rng=3)
    assert again.v50_bootstrap_ci_m_s == few.v50_bootstrap_ci_m_s
    other = fit_v50(speed, perforated, bootstrap=50, rng=4)
    assert other.v50_bootstrap_ci_m_s != few.v50_bootstrap_ci_m_s


def test_bootstrap_resamples_that_separate_enter_as_a_step():
    """Eight shots with one overlap (the no-go at 505 m/s above the go at 500 m/s): many
    resamples separate, each as σ = 0, so the σ interval starts at 0."""
    speed = np.array([470.0, 480.0, 490.0, 505.0, 500.0, 510.0, 520.0, 530.0])
    perforated = np.array([False, False, False, False, True, True, True, True])
    fit = fit_v50(speed, perforated, bootstrap=200)
    assert fit.bootstrap_separated > 0.025 * 200
    assert fit.sigma_bootstrap_ci_m_s[0] == 0.0
    assert fit.mixed_zone_m_s == (500.0, 505.0)


@pytest.mark.parametrize(
    ("speed", "perforated", "words"),
    [
        ([480.0, 490.0, 510.0, 520.0], [0, 0, 1, 1], "no zone of mixed results"),
        ([480.0, 500.0, 500.0, 520.0], [0, 0, 1, 1], "no zone of mixed results"),
        ([480.0, 500.0, 520.0], [0, 1, 1], "too few shots"),
        ([480.0, 500.0, 520.0, 530.0], [1, 1, 1, 1], "too few shots"),
        ([480.0, 500.0, 520.0, 530.0, 540.0], [1, 0, 1, 0, 0], "no ballistic limit"),
    ],
)
def test_shots_no_fit_can_take_are_refused_in_one_line(speed, perforated, words):
    with pytest.raises(V50Error, match=words) as caught:
        fit_v50(speed, perforated, label="s.csv at 0 deg")
    assert "\n" not in str(caught.value) and str(caught.value).startswith("s.csv at 0 deg: ")


@pytest.mark.parametrize(
    ("options", "parameter"),
    [
        ({"method": "cloglog"}, "method"),
        ({"confidence": 1.0}, "confidence"),
        ({"confidence": math.nan}, "confidence"),
        ({"bootstrap": -1}, "bootstrap"),
        ({"bootstrap": 2.5}, "bootstrap"),
        ({"weight": [1, 1, -1, 1, 1]}, "weight"),
        ({"weight": [1, 1, 2e9, 1, 1]}, "weight"),  # more shots than a row can stand for
        ({"weight": [1, 1, math.nan, 1, 1]}, "weight"),
    ],
)
def test_bad_options_are_parameter_errors(options, parameter):
    speed, perforated = [480.0, 490.0, 500.0, 510.0, 520.0], [0, 1, 0, 1, 1]
    with pytest.raises(ParameterError) as caught:
        fit_v50(speed, perforated, **options)
    assert caught.value.parameter == parameter


#: Four partial penetrations (no-go) and four complete ones (go) [m/s].
PARTIAL = [470.0, 488.0, 497.0, 505.0]
COMPLETE = [499.0, 512.0, 520.0, 540.0]
SPEEDS = np.array(PARTIAL + COMPLETE)
GO = np.array([False] * 4 + [True] * 4)


def test_mil_std_662f_on_a_hand_worked_example():
    """Partials 470, 488, 497, 505 m/s; completes 499, 512, 520, 540 m/s.

    Six rounds (3 of each): the highest partials 505, 497, 488 and the lowest completes
    499, 512, 520 span 520 − 488 = 32 m/s <= 38.1 m/s; V50 = (505 + 497 + 488 + 499 + 512
    + 520)/6 = 3021/6 = 503.5 m/s. Ten rounds need 5 of each: there are 4, so six is the
    most. Four rounds (2 of each): 505, 497, 499, 512 span 512 − 497 = 15 m/s; V50 =
    2013/4 = 503.25 m/s. With a 30 m/s span six rounds (32 m/s) are refused.
    """
    found = mil_std_662f(SPEEDS, GO)
    assert (found.count, found.rounds) == (3, 6)
    assert found.v50_m_s == pytest.approx(503.5, abs=1e-12)
    assert found.spread_m_s == pytest.approx(32.0, abs=1e-12)
    assert found.spread_allowed_m_s == pytest.approx(38.1, abs=1e-12)
    assert found.partial_speeds_m_s == (505.0, 497.0, 488.0)
    assert found.complete_speeds_m_s == (499.0, 512.0, 520.0)
    assert sorted(found.used) == [1, 2, 3, 4, 5, 6]
    four = mil_std_662f(SPEEDS, GO, count=2)
    assert (four.v50_m_s, four.spread_m_s) == (pytest.approx(503.25), pytest.approx(15.0))
    with pytest.raises(V50Error, match="span 32 m/s, more than the 30 m/s allowed"):
        mil_std_662f(SPEEDS, GO, count=3, spread_m_s=30.0)
    assert mil_std_662f(SPEEDS, GO, spread_m_s=30.0).count == 2  # the most that fit


def test_mil_std_662f_counts_weights_as_rounds_and_refuses_what_the_standard_does():
    weighted = mil_std_662f([497.0, 505.0, 499.0, 512.0], [0, 0, 1, 1], [2, 1, 1, 2])
    # rounds 505, 497, 497 | 499, 512, 512: (505 + 2·497 + 499 + 2·512)/6
    assert weighted.v50_m_s == pytest.approx((505 + 2 * 497 + 499 + 2 * 512) / 6)
    with pytest.raises(V50Error, match="needs at least 5 partial and 5 complete"):
        mil_std_662f(SPEEDS, GO, count=5)
    with pytest.raises(V50Error, match="at least 2 partial and 2 complete"):
        mil_std_662f([490.0, 500.0, 510.0], [0, 1, 1])
    with pytest.raises(ParameterError, match="count must be one of 2, 3, 5"):
        mil_std_662f(SPEEDS, GO, count=4)
    with pytest.raises(ParameterError, match="whole numbers"):
        mil_std_662f(SPEEDS, GO, np.full(8, 0.5))
