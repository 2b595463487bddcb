"""Uncertainty propagation (docs/uncertainty.md) against closed forms: the probability of
perforation at normal incidence with only the impact speed uncertain is P(Vs > V_bl) for
the ballistic limit's closed form; the sampling methods' marginals are their
distributions (stratified for Latin hypercube and Sobol' points); a spec's bad value is
one line naming its key; a seeded study is the same bits twice."""

from __future__ import annotations

import json
import math

import numpy as np
import pytest
from closed_forms import ballistic_limit
from scipy import stats

import plateimpact as pi
from plateimpact import presets
from plateimpact.cli import main
from plateimpact.model.impact import REST_SPEED_FRACTION
from plateimpact.uncertainty import (
    LogNormal,
    Normal,
    TruncatedNormal,
    Uniform,
    propagate,
    read_spec,
)
from plateimpact.uncertainty.curves import outcome_grid
from plateimpact.uncertainty.limits import sampled_limits
from plateimpact.uncertainty.propagation import (
    binomial_intervals,
    sample_inputs,
    scenes,
    study_name,
    unit_samples,
)
from plateimpact.uncertainty.sensitivity import perforation_indices, sobol_indices
from plateimpact.uncertainty.spec import UncertaintySpecError

PRESET = "2024-T3/3.18"
SPHERE = presets.DEFAULT_SPHERE


@pytest.fixture(scope="module")
def registry():
    return pi.default_registry()


def closed_form_ballistic_limit(plate: pi.Plate) -> float:
    """V_bl at normal incidence with plugging (tests/closed_forms.py)."""
    return ballistic_limit(plate, SPHERE, REST_SPEED_FRACTION.default)


def speed_only(mean: float, sd: float, method: str, samples: int, seed: int = 3) -> dict:
    return {
        "preset": PRESET,
        "failure": "plugging",
        "at": {"obliquity_deg": 0.0},
        "inputs": {"speed_m_s": {"normal": {"mean": mean, "sd": sd}}},
        "samples": samples,
        "method": method,
        "seed": seed,
    }


@pytest.mark.parametrize("method", ["mc", "sobol"])
@pytest.mark.parametrize("offset", [-1.0, 0.0, 0.6])
def test_perforation_probability_is_that_of_the_closed_form_limit(registry, method, offset):
    """P(perforation) = 1 − Φ((V_bl − μ)/σ), inside the study's interval (at 99.9%, so
    that the check does not depend on the seed's luck: 6 cases fail together with
    probability under 1%)."""
    limit = closed_form_ballistic_limit(presets.plate(PRESET))
    sd = 20.0
    mean = limit + offset * sd
    spec = read_spec(speed_only(mean, sd, method, 4096), registry)
    found = propagate(spec, registry, confidence=0.999)
    exact = 1.0 - stats.norm.cdf((limit - mean) / sd)
    low, high = found.intervals()["perforation"]
    assert low <= exact <= high, (exact, low, high)
    assert found.counts["ricochet"] == 0  # normal incidence never turns back
    assert found.counts["embedment"] + found.counts["perforation"] == 4096


@pytest.mark.parametrize("method", ["lhs", "sobol"])
def test_stratified_points_fill_every_stratum_once(method):
    """n = 2^10 points: each of the n equal strata of every coordinate holds exactly one
    (a Latin hypercube by construction; a scrambled Sobol' net of 2^m points too), so
    the empirical distribution is within 1/n of the uniform one."""
    n = 1024
    points = unit_samples(method, n, 3, seed=11)
    for column in points.T:
        assert np.array_equal(np.sort(np.floor(column * n)), np.arange(n))


@pytest.mark.parametrize("n", [2, 7, 60, 2000, 100_000])
def test_binomial_intervals_are_scipys_exact_ones(n):
    """The Clopper–Pearson interval from beta quantiles, all counts at once, is the one
    scipy.stats.binomtest finds by root-finding, count by count."""
    counts = np.unique(np.linspace(0, n, min(n + 1, 60)).astype(int))
    low, high = binomial_intervals(counts, n, 0.95)
    for k, lo, hi in zip(counts, low, high, strict=True):
        ci = stats.binomtest(int(k), n).proportion_ci(0.95, method="exact")
        assert lo == pytest.approx(ci.low, abs=1e-11) and hi == pytest.approx(ci.high, abs=1e-11)


def test_independent_draws_pass_a_uniformity_test():
    points = unit_samples("mc", 5000, 2, seed=11)
    for column in points.T:
        assert stats.kstest(column, "uniform").statistic < 1.63 / math.sqrt(5000)  # 99%


@pytest.mark.parametrize(
    "distribution, median, inside",
    [
        (Normal(10.0, 2.0), 10.0, (-np.inf, np.inf)),
        (LogNormal(3.0, 0.5), 3.0, (0.0, np.inf)),
        (Uniform(1.0, 5.0), 3.0, (1.0, 5.0)),
        (TruncatedNormal(0.0, 1.0, -0.5, 2.0), None, (-0.5, 2.0)),
    ],
)
def test_each_distribution_maps_probabilities_to_values(distribution, median, inside):
    u = np.linspace(0.001, 0.999, 999)
    values = distribution.ppf(u)
    assert np.all(np.diff(values) > 0) and inside[0] <= values[0] and values[-1] <= inside[1]
    if median is not None:
        assert distribution.ppf(np.array([0.5]))[0] == pytest.approx(median, rel=1e-12)
    for x, p in zip(values[::100], u[::100], strict=True):  # cdf inverts ppf
        assert distribution.cdf(float(x)) == pytest.approx(p, abs=1e-9)


def test_a_seeded_study_is_the_same_bits_twice(registry):
    given = speed_only(600.0, 30.0, "lhs", 500, seed=9)
    given["inputs"]["pstar_mm"] = {"uniform": {"low": 2.0, "high": 4.0}}
    first = propagate(read_spec(given, registry), registry)
    second = propagate(read_spec(given, registry), registry)
    for name in first.inputs:
        assert np.array_equal(first.inputs[name], second.inputs[name])
    assert np.array_equal(first.result.outcome, second.result.outcome)
    assert np.array_equal(first.result.exit_speed, second.result.exit_speed)
    given["seed"] = 10
    other = propagate(read_spec(given, registry), registry)
    assert not np.array_equal(first.inputs["speed_m_s"], other.inputs["speed_m_s"])


def test_sampled_values_set_their_columns(registry):
    """P* in mm and the speed in m/s reach the scenes in SI."""
    given = speed_only(600.0, 30.0, "mc", 200)
    given["inputs"]["pstar_mm"] = {"uniform": {"low": 2.0, "high": 4.0}}
    found = propagate(read_spec(given, registry), registry)
    batch = scenes(found.spec, found.inputs, registry)
    assert np.array_equal(batch.columns["critical_penetration"], found.inputs["pstar_mm"] * 1e-3)
    assert np.array_equal(batch.columns["impact_speed"], found.inputs["speed_m_s"])
    assert np.all(batch.columns["impact_obliquity"] == 0.0)


@pytest.mark.parametrize(
    "change, said",
    [
        ({"inputs": {"pstar_mm": {"normal": {"mean": 0.5, "sd": 1.0}}}}, "inputs.pstar_mm"),
        ({"inputs": {"obliquity_deg": {"uniform": {"low": 10, "high": 95}}}}, "[0, 90) deg"),
        ({"inputs": {"speed_m_s": {"gamma": {"k": 2}}}}, "unknown distribution"),
        ({"inputs": {"speed_m_s": {"normal": {"mean": 400}}}}, "takes exactly mean, sd"),
        ({"inputs": {"speed_m_s": {"normal": {"mean": 400, "sd": -1}}}}, "sd must be > 0"),
        ({"inputs": {"speed_m_s": {"normal": {"mean": "fast", "sd": 1}}}}, "a number is needed"),
        ({"inputs": {"sped_m_s": {"fixed": {"value": 1}}}}, "sped_m_s: unknown input"),
        ({"at": {"obliquity_deg": 91}}, "at.obliquity_deg"),
        ({"samples": 1}, "samples: an integer"),
        ({"method": "halton"}, "method: one of mc, sobol, lhs"),
        ({"seed": -1}, "seed: an integer"),
        ({"preset": "unobtainium"}, "preset: one of"),
        ({"extra": 1}, "unknown key 'extra'"),
    ],
)
def test_a_bad_spec_is_one_line_naming_its_key(registry, change, said):
    given = speed_only(400.0, 15.0, "mc", 100)
    given.update(change)
    with pytest.raises(UncertaintySpecError, match=None) as raised:
        read_spec(given, registry)
    message = str(raised.value)
    assert said in message and "\n" not in message


def test_a_truncated_normal_inside_the_range_is_accepted(registry):
    given = speed_only(400.0, 15.0, "mc", 100)
    given["inputs"]["pstar_mm"] = {"truncnormal": {"mean": 0.5, "sd": 1.0, "low": 0.01, "high": 3}}
    spec = read_spec(given, registry)
    found = propagate(spec, registry)
    assert 0.01 <= found.inputs["pstar_mm"].min() and found.inputs["pstar_mm"].max() <= 3.0


def test_the_command_prints_probabilities_and_intervals(tmp_path, capsys):
    path = tmp_path / "spec.json"
    path.write_text(json.dumps(speed_only(400.0, 15.0, "mc", 300)))
    assert main(["uncertainty", str(path), "--json", "--samples", "256", "--method", "sobol"]) == 0
    said = json.loads(capsys.readouterr().out)
    assert said["samples"] == 256 and said["method"] == "sobol"
    assert (
        set(said["probabilities"])
        == set(said["intervals"])
        == {
            "ricochet",
            "embedment",
            "perforation",
        }
    )
    assert sum(said["probabilities"].values()) == pytest.approx(1.0)
    assert said["model"]["failure"] == "plugging" and "plateimpact" in said["versions"]
    for name, (low, high) in said["intervals"].items():
        assert low <= said["probabilities"][name] <= high


def test_the_command_refuses_a_bad_spec_in_one_line(tmp_path, capsys):
    path = tmp_path / "spec.json"
    path.write_text('{"preset": "2024-T3/3.18", "at": {"speed_m_s": 400}}')
    assert main(["uncertainty", str(path)]) == 2
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and "obliquity_deg: give it in at or in inputs" in err


def pstar_only(samples: int, seed: int = 4) -> dict:
    return {
        "preset": PRESET,
        "failure": "plugging",
        "at": {"obliquity_deg": 0.0},
        "inputs": {"pstar_mm": {"uniform": {"low": 2.5, "high": 3.5}}},
        "samples": samples,
        "seed": seed,
    }


@pytest.fixture(scope="module")
def sampled(registry):
    return sampled_limits(read_spec(pstar_only(120), registry), registry, 0.0)


def test_each_sampled_limit_is_its_plates_closed_form(sampled):
    """With only P* uncertain at normal incidence, every sample's ballistic limit is the
    closed form for its P*, to the finder's tolerance."""
    plate = presets.plate(PRESET)
    for pstar_mm, found in zip(sampled.inputs["pstar_mm"], sampled.ballistic, strict=True):
        constants = {**dict(plate.constants), "critical_penetration": pstar_mm * 1e-3}
        own = pi.Plate(plate.material, plate.thickness, tuple(constants.items()))
        assert found == pytest.approx(
            closed_form_ballistic_limit(own), abs=sampled.tolerance / 2 + 1e-6
        )


@pytest.mark.parametrize("speed", [360.0, 395.0, 430.0])
def test_the_curve_from_sampled_limits_is_per_speed_monte_carlo(registry, sampled, speed):
    """P(perforation | V) read off the sampled limits counts the same samples as running
    each sample at V (the same seed draws the same P*), except a sample whose limit lies
    within the finder's tolerance of V."""
    given = pstar_only(120)
    given["at"]["speed_m_s"] = speed
    direct = propagate(read_spec(given, registry), registry)
    assert np.array_equal(direct.inputs["pstar_mm"], sampled.inputs["pstar_mm"])
    perforated = direct.result.outcome == pi.Outcome.PERFORATION
    below = sampled.ballistic < speed
    close = np.abs(sampled.ballistic - speed) <= sampled.tolerance
    assert np.array_equal(perforated[~close], below[~close])
    probability, low, high = sampled.perforation_curve(np.array([speed]))
    assert low[0] <= direct.probabilities()["perforation"] <= high[0]
    assert probability[0] == pytest.approx(np.mean(below))


def test_quantiles_of_the_limit_bracket_the_sample_quantile(sampled):
    v50 = sampled.quantile(0.5)
    assert v50["low_m_s"] <= v50["speed_m_s"] <= v50["high_m_s"]
    assert v50["speed_m_s"] == np.quantile(sampled.ballistic, 0.5, method="inverted_cdf")
    v10, v90 = sampled.quantile(0.1), sampled.quantile(0.9)
    assert v10["speed_m_s"] < v50["speed_m_s"] < v90["speed_m_s"]


def test_the_limit_refuses_an_uncertain_speed(registry):
    spec = read_spec(speed_only(400.0, 15.0, "mc", 10), registry)
    with pytest.raises(pi.ParameterError, match="give speed_m_s no distribution"):
        sampled_limits(spec, registry, 0.0)


def test_the_command_prints_the_limits_quantiles(tmp_path, capsys):
    path = tmp_path / "spec.json"
    path.write_text(json.dumps(pstar_only(40)))
    assert main(["uncertainty", str(path), "--limits", "--json"]) == 0
    said = json.loads(capsys.readouterr().out)
    (row,) = said["limits"]
    assert said["samples"] == 40 and row["obliquity_deg"] == 0.0
    ballistic = row["ballistic_limit"]  # the keys of plateimpact v50
    assert ballistic["v10_m_s"] < ballistic["v50_m_s"] < ballistic["v90_m_s"]
    low, high = ballistic["v50_ci_m_s"]
    assert low <= ballistic["v50_m_s"] <= high
    assert said["spec"]["inputs"] == {"pstar_mm": {"uniform": {"low": 2.5, "high": 3.5}}}


def ishigami(values: dict[str, np.ndarray], a: float = 7.0, b: float = 0.1) -> np.ndarray:
    x1, x2, x3 = values["x1"], values["x2"], values["x3"]
    return np.sin(x1) + a * np.sin(x2) ** 2 + b * x3**4 * np.sin(x1)


def test_sobol_indices_of_the_ishigami_function_are_its_analytical_ones():
    """S1 = (0.314, 0.442, 0), ST = (0.558, 0.442, 0.244) for a = 7, b = 0.1 (Ishigami
    and Homma 1990; Sobol' and Levitan 1999), inside the 99% bootstrap intervals."""
    a, b, pi4 = 7.0, 0.1, np.pi**4
    variance = a**2 / 8 + b * pi4 / 5 + b**2 * pi4**2 / 18 + 0.5
    v1, v2, v13 = 0.5 * (1 + b * pi4 / 5) ** 2, a**2 / 8, 8 * b**2 * pi4**2 / 225
    first = np.array([v1, v2, 0.0]) / variance
    total = np.array([v1 + v13, v2, v13]) / variance
    inputs = {name: Uniform(-np.pi, np.pi) for name in ("x1", "x2", "x3")}
    found = sobol_indices(inputs, ishigami, 2**13, seed=5, confidence=0.99)
    assert found.evaluations == 2**13 * 5
    assert np.all(np.abs(found.first - first) <= found.first_halfwidth)
    assert np.all(np.abs(found.total - total) <= found.total_halfwidth)
    assert found.dominant() == "x1"


def test_perforation_indices_on_the_model_are_variance_shares(registry):
    """On the model, the first-order indices of whether a sample perforates sum to at
    most 1 and no total index is below its first-order one (to their intervals); at
    normal incidence the speed's spread of 30 m/s outweighs P*'s ± 0.1 mm."""
    given = {
        "preset": PRESET,
        "failure": "plugging",
        "at": {"obliquity_deg": 0.0},
        "inputs": {
            "speed_m_s": {"normal": {"mean": 392.0, "sd": 30.0}},
            "pstar_mm": {"uniform": {"low": 2.9, "high": 3.1}},
        },
        "seed": 3,
    }
    found = perforation_indices(read_spec(given, registry), registry, 2**9)
    assert found.first.sum() <= 1.0 + found.first_halfwidth.sum()
    assert np.all(found.total >= found.first - found.first_halfwidth - found.total_halfwidth)
    assert found.dominant() == "speed_m_s"


def test_the_command_prints_sobol_indices_and_draws_their_bars(tmp_path, capsys):
    given = speed_only(392.0, 30.0, "mc", 100)
    given["inputs"]["pstar_mm"] = {"uniform": {"low": 2.9, "high": 3.1}}
    path, png = tmp_path / "spec.json", tmp_path / "bars.png"
    path.write_text(json.dumps(given))
    argv = ["uncertainty", str(path), "--sobol", "64", "--png", str(png), "--dpi", "50", "--json"]
    assert main(argv) == 0
    said = json.loads(capsys.readouterr().out)["perforation"]
    assert said["evaluations"] == 64 * 4 and set(said["indices"]) == {"speed_m_s", "pstar_mm"}
    assert png.read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"


@pytest.mark.parametrize(
    "extra, said",
    [
        (["--sobol", "100"], "--sobol: a power of 2"),
        (["--png", "x.png"], "--png draws the limits' curves, the Sobol' indices or the"),
        (["--sobol", "64", "--limits"], "--sobol: not with --limits"),
        (["--sobol", "64", "--samples", "100"], "--samples: not with --sobol"),
        (["--sobol-of", "both"], "--sobol-of says what --sobol N analyses"),
        (["--sobol", "64", "--sobol-of", "ballistic_limit"], "inputs.speed_m_s without a"),
    ],
)
def test_the_command_refuses_bad_sobol_flags_in_one_line(tmp_path, capsys, extra, said):
    path = tmp_path / "spec.json"
    path.write_text(json.dumps(speed_only(392.0, 30.0, "mc", 100)))
    assert main(["uncertainty", str(path), *extra]) == 2
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and said in err


@pytest.fixture(scope="module")
def calibrated(tmp_path_factory):
    """A plate file as calibrate --out writes it, from the studies' 2024-T3 shots."""
    from pathlib import Path

    shots = Path(__file__).resolve().parents[1] / "studies" / "data" / "shots_2024T3_3.18mm.csv"
    out = tmp_path_factory.mktemp("calibrated") / "cal.json"
    assert main(["calibrate", str(shots), "--preset", PRESET, "--out", str(out)]) == 0
    return out


def test_a_calibration_file_gives_a_and_b_their_joint_normal(registry, calibrated):
    """a and b are normal with the file's values and standard errors, correlated as its
    ab_correlation says (a Gaussian copula of normal marginals: exactly a bivariate
    normal): the sample moments within a few standard errors of 20,000 draws."""
    written = json.loads(calibrated.read_text())
    block = written["calibration"]
    given = {
        "plate_file": calibrated.name,
        "calibration_file": calibrated.name,
        "at": {"speed_m_s": 400.0, "obliquity_deg": 0.0},
        "samples": 20_000,
        "seed": 2,
    }
    spec_path = calibrated.parent / "spec.json"
    spec_path.write_text(json.dumps(given))
    spec = read_spec(spec_path, registry)
    assert spec.correlations == (("a_N_m2", "b_kg_m3", block["ab_correlation"]),)
    values = sample_inputs(spec)
    a, b = values["a_N_m2"], values["b_kg_m3"]
    rho = block["ab_correlation"]
    assert -1 < rho < 0  # a stronger plate fits with a lighter inertial term
    assert np.corrcoef(a, b)[0, 1] == pytest.approx(rho, abs=5 * (1 - rho**2) / math.sqrt(a.size))
    assert a.mean() == pytest.approx(written["a_N_m2"], abs=5 * block["a_stderr_N_m2"] / 141)
    assert a.std() == pytest.approx(block["a_stderr_N_m2"], rel=0.05)
    assert b.std() == pytest.approx(block["b_stderr_kg_m3"], rel=0.05)


@pytest.mark.parametrize(
    "correlations, said",
    [
        ([["speed_m_s", "pstar_mm", 1.2]], "rho in (-1, 1)"),
        ([["speed_m_s", "pstar_mm", 0.5], ["pstar_mm", "speed_m_s", 0.1]], "appears twice"),
        ([["speed_m_s", "a_N_m2", 0.5]], "a_N_m2 has no distribution"),
        (
            [
                ["speed_m_s", "pstar_mm", 0.9],
                ["speed_m_s", "b_kg_m3", 0.9],
                ["pstar_mm", "b_kg_m3", -0.9],
            ],
            "not positive definite",
        ),  # fmt: skip
        ({"speed_m_s": 1}, "a list of [input, input, rho]"),
    ],
)
def test_bad_correlations_are_one_line(registry, correlations, said):
    given = speed_only(400.0, 15.0, "mc", 100)
    given["inputs"]["pstar_mm"] = {"uniform": {"low": 2.5, "high": 3.5}}
    given["inputs"]["b_kg_m3"] = {"uniform": {"low": 1000, "high": 1500}}
    given["correlations"] = correlations
    with pytest.raises(UncertaintySpecError) as raised:
        read_spec(given, registry)
    assert said in str(raised.value) and "\n" not in str(raised.value)


def test_sobol_indices_refuse_correlated_inputs(registry):
    given = speed_only(400.0, 15.0, "mc", 100)
    given["inputs"]["pstar_mm"] = {"uniform": {"low": 2.5, "high": 3.5}}
    given["correlations"] = [["speed_m_s", "pstar_mm", 0.3]]
    with pytest.raises(UncertaintySpecError, match="need independent inputs"):
        perforation_indices(read_spec(given, registry), registry, 16)


def test_a_seeded_study_on_a_two_process_pool_is_the_same_bits(registry):
    from concurrent.futures import ProcessPoolExecutor

    given = speed_only(600.0, 30.0, "sobol", 600, seed=5)
    given["inputs"]["pstar_mm"] = {"uniform": {"low": 2.0, "high": 4.0}}
    spec = read_spec(given, registry)
    alone = propagate(spec, registry)
    with ProcessPoolExecutor(2) as pool:
        pooled = propagate(spec, registry, executor=pool)
    assert np.array_equal(alone.result.outcome, pooled.result.outcome)
    assert np.array_equal(alone.result.exit_speed, pooled.result.exit_speed)
    assert np.array_equal(alone.result.exit_obliquity, pooled.result.exit_obliquity)


def test_the_probability_curve_along_speed_is_the_sampled_limits_curve(registry, sampled):
    """The same seed draws the same P* samples for the curve and for the sampled limits:
    at every speed the curve's perforations are the samples whose limit lies below it,
    apart from a sample whose limit is within the finder's tolerance of the speed."""
    speeds = np.array([360.0, 380.0, 395.0, 410.0, 430.0])
    grid = outcome_grid(read_spec(pstar_only(120), registry), registry, speeds)
    assert grid.counts["perforation"].shape == (speeds.size, 1)
    for i, speed in enumerate(speeds):
        below = sampled.ballistic < speed
        close = int(np.sum(np.abs(sampled.ballistic - speed) <= sampled.tolerance))
        assert abs(int(grid.counts["perforation"][i, 0]) - int(below.sum())) <= close
    perforation = grid.probabilities()["perforation"][:, 0]
    assert np.all(np.diff(perforation) >= 0)  # common samples: monotone in speed here


def test_a_grid_over_the_plane_counts_every_sample_once_per_point(registry):
    grid = outcome_grid(
        read_spec(pstar_only(50), registry), registry, np.array([300.0, 600.0]),
        np.array([0.0, 45.0, 75.0]),
    )  # fmt: skip
    total = sum(grid.counts.values())
    assert total.shape == (2, 3) and np.all(total == 50)
    low, high = grid.intervals()["ricochet"]
    assert np.all(low <= grid.probabilities()["ricochet"])
    assert np.all(grid.probabilities()["ricochet"] <= high)


def test_a_grid_input_takes_no_distribution(registry):
    spec = read_spec(speed_only(400.0, 15.0, "mc", 10), registry)
    with pytest.raises(UncertaintySpecError, match="a grid of it takes no distribution"):
        outcome_grid(spec, registry, np.array([300.0, 400.0]))


def test_the_command_prints_a_probability_curve(tmp_path, capsys):
    path = tmp_path / "spec.json"
    path.write_text(json.dumps(pstar_only(30)))
    assert main(["uncertainty", str(path), "--speeds", "300:500:3", "--json"]) == 0
    said = json.loads(capsys.readouterr().out)
    assert said["speeds_m_s"] == [300.0, 400.0, 500.0] and said["obliquities_deg"] == [0.0]
    assert np.shape(said["probabilities"]["perforation"]) == (3, 1)


def test_an_archived_study_is_read_back_on_resume(registry, tmp_path, monkeypatch):
    """The samples run as a study of the archive, named by the spec; resuming reads the
    finished run back (no scene runs again: run_batch made to fail) with the same bits;
    the study records the spec it sampled."""
    given = speed_only(400.0, 15.0, "lhs", 300, seed=8)
    spec = read_spec(given, registry)
    archive = tmp_path / "u.h5"
    first = propagate(spec, registry, archive=archive)
    monkeypatch.setattr(
        pi.Simulation, "run_batch", lambda *a, **k: pytest.fail("a scene ran again")
    )
    again = propagate(spec, registry, archive=archive, resume=True)
    assert np.array_equal(first.result.outcome, again.result.outcome)
    assert np.array_equal(first.result.exit_speed, again.result.exit_speed)
    stored = pi.Study.from_archive(archive, study_name(spec))
    assert json.loads(stored.description) == json.loads(json.dumps(spec.describe()))
    assert np.array_equal(stored.scenes.columns["impact_speed"], first.inputs["speed_m_s"])


def test_the_command_keeps_an_archived_run_unless_resumed(tmp_path, capsys):
    path, archive = tmp_path / "spec.json", tmp_path / "u.h5"
    path.write_text(json.dumps(speed_only(400.0, 15.0, "mc", 200)))
    assert main(["uncertainty", str(path), "--archive", str(archive), "--json"]) == 0
    first = json.loads(capsys.readouterr().out)
    assert main(["uncertainty", str(path), "--archive", str(archive)]) == 2
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and "already has run" in err
    argv = ["uncertainty", str(path), "--archive", str(archive), "--resume", "--json"]
    assert main(argv) == 0
    assert json.loads(capsys.readouterr().out)["probabilities"] == first["probabilities"]


@pytest.mark.parametrize(
    "extra, said",
    [
        (["--samples", "1"], "--samples: an integer in [2, 10,000,000]"),
        (["--seed", "-1"], "--seed: an integer in [0, 2**63)"),
        (["--resume"], "--resume reads back a result of --archive"),
        (["--archive", "u.h5", "--shots", "s.csv"], "--shots go beside the sampled limits"),
        (["--archive", "u.h5", "--limits", "--speeds", "300"], "--speeds: not with --limits"),
        (["--speeds", "a:b:c"], "--speeds"),
    ],
)
def test_the_commands_flags_refuse_bad_values_in_one_line(tmp_path, capsys, extra, said):
    path = tmp_path / "spec.json"
    path.write_text(json.dumps(speed_only(392.0, 30.0, "mc", 100)))
    assert main(["uncertainty", str(path), *extra]) == 2
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and said in err, err
    assert not (tmp_path / "u.h5").exists()
