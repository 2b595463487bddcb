"""``plateimpact v50``: what it prints is the API's fit of the file's shots, per obliquity;
the model's ballistic limit beside it; the MIL-STD-662F estimate; one line and exit code
2 for shots no estimate can take and for options of the other method."""

from __future__ import annotations

import json
import os
from pathlib import Path

import numpy as np
import pytest
from scipy import stats

import plateimpact as pi
from plateimpact import presets
from plateimpact.cli import main
from plateimpact.v50 import fit_v50, mil_std_662f

HEADER = "impact_speed_m_s,impact_obliquity_deg,perforated"
#: (obliquity [deg], V50 [m/s], σ [m/s]) of the curves the shots are drawn from.
CURVES = ((0.0, 330.0, 20.0), (45.0, 420.0, 15.0))


def drawn(seed: int, v50: float, sigma: float, count: int = 24) -> tuple[np.ndarray, np.ndarray]:
    rng = np.random.default_rng(seed)
    speed = np.round(rng.uniform(v50 - 2.5 * sigma, v50 + 2.5 * sigma, count), 1)
    return speed, rng.random(count) < stats.norm.cdf((speed - v50) / sigma)


@pytest.fixture(scope="module")
def shots_csv(tmp_path_factory):
    """24 go/no-go shots at each of 0 and 45 deg, drawn from CURVES."""
    rows = [HEADER]
    for k, (obliquity, v50, sigma) in enumerate(CURVES):
        speed, perforated = drawn(k, v50, sigma)
        pairs = zip(speed, perforated, strict=True)
        rows += [f"{float(v)!r},{obliquity},{int(p)}" for v, p in pairs]
    path = tmp_path_factory.mktemp("v50") / "gonogo.csv"
    path.write_text("\n".join(rows) + "\n")
    return path


def run_json(capsys, *args: str):
    assert main(["v50", *map(str, args), "--json"]) == 0
    return json.loads(capsys.readouterr().out)


def test_one_obliquity_prints_one_object_the_apis_fit_of_the_file(tmp_path, capsys):
    speed, perforated = drawn(0, 330.0, 20.0)
    outcome = np.where(perforated, "perforation", "embedment")  # perforated told by outcome
    path = tmp_path / "one.csv"
    path.write_text(
        "impact_speed_m_s,impact_obliquity_deg,outcome\n"
        + "".join(f"{float(v)!r},30,{o}\n" for v, o in zip(speed, outcome, strict=True))
    )
    out = run_json(capsys, path, "--method", "logit", "--bootstrap", "50", "--seed", "7")
    fit = fit_v50(speed, perforated, method="logit", bootstrap=50, rng=7)
    assert out["obliquity_deg"] == 30.0 and out["method"] == "logit"
    for key in ("v50_m_s", "sigma_m_s", "v10_m_s", "v90_m_s", "shots"):
        assert out[key] == getattr(fit, key)
    for key in ("v50_ci_m_s", "sigma_ci_m_s", "v50_bootstrap_ci_m_s", "sigma_bootstrap_ci_m_s"):
        assert out[key] == list(getattr(fit, key))


def test_by_obliquity_prints_a_list_and_the_models_ballistic_limit(shots_csv, capsys):
    out = run_json(capsys, shots_csv, "--by-obliquity", "--bootstrap", "0",
                   "--preset", "SAE1010/1.47")  # fmt: skip
    assert [row["obliquity_deg"] for row in out] == [0.0, 45.0]
    limits = pi.limits.along_speed(
        pi.Simulation.from_names(), presets.DEFAULT_SPHERE, presets.plate("SAE1010/1.47"),
        np.radians([0.0, 45.0]), (50.0, 2000.0),
    )  # fmt: skip
    for k, (row, (_, v50, sigma)) in enumerate(zip(out, CURVES, strict=True)):
        fit = fit_v50(*drawn(k, v50, sigma), bootstrap=0)
        assert row["v50_m_s"] == fit.v50_m_s and row["v50_ci_m_s"] == list(fit.v50_ci_m_s)
        assert row["v50_bootstrap_ci_m_s"] is None and row["bootstrap_resamples"] == 0
        assert row["model_ballistic_limit_m_s"] == pytest.approx(
            limits.lines[k].ballistic_limit, abs=0.01
        )
        assert row["model"] == "SAE1010/1.47, poncelet + plugging"


def test_mil_std_662f_through_the_command(tmp_path, capsys):
    """The hand-worked example of test_v50 (V50 503.5 m/s from six rounds spanning 32 m/s),
    its rounds named by the file's lines."""
    speeds = [470.0, 488.0, 497.0, 505.0, 499.0, 512.0, 520.0, 540.0]
    path = tmp_path / "six.csv"
    path.write_text(HEADER + "\n" + "".join(
        f"{v},0,{int(k >= 4)}\n" for k, v in enumerate(speeds)))  # fmt: skip
    out = run_json(capsys, path, "--method", "mil-std-662f")
    assert out["v50_m_s"] == pytest.approx(503.5) and out["spread_m_s"] == pytest.approx(32.0)
    assert out["rounds"] == 6 and out["spread_allowed_m_s"] == pytest.approx(38.1)
    assert sorted(out["used"]) == sorted(f"{path} line {n}" for n in range(3, 9))
    assert out["sigma_m_s"] is None and out["v50_ci_m_s"] is None
    out = run_json(capsys, path, "--method", "mil-std-662f", "--count", "2", "--spread", "20")
    assert out["v50_m_s"] == pytest.approx(503.25) and out["rounds"] == 4


def test_text_and_figure(shots_csv, tmp_path, capsys):
    png = tmp_path / "v50.png"
    args = ["v50", str(shots_csv), "--by-obliquity", "--bootstrap", "100",
            "--preset", "SAE1010/1.47", "--png", str(png)]  # fmt: skip
    assert main(args) == 0
    out = capsys.readouterr().out
    fit = fit_v50(*drawn(1, 420.0, 15.0), bootstrap=0)
    assert f"{shots_csv} at 45 deg: 24 shots" in out and f"{fit.v50_m_s:9.4g} m/s" in out
    assert out.count("model (SAE1010/1.47, poncelet + plugging): ballistic limit") == 2
    assert f"figure: {png}" in out and png.read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"


def test_a_group_without_a_v50_is_said_so_beside_the_others(shots_csv, tmp_path, capsys):
    path = tmp_path / "three.csv"
    separated = "".join(f"{v},30,{int(v > 315)}\n" for v in (300, 310, 320, 330))
    path.write_text(shots_csv.read_text() + separated)
    out = run_json(capsys, path, "--by-obliquity", "--bootstrap", "0")
    assert [row["obliquity_deg"] for row in out] == [0.0, 30.0, 45.0]
    assert out[1]["error"].startswith("no zone of mixed results") and "v50_m_s" not in out[1]
    assert mil_std_662f([300, 310, 320, 330], [0, 0, 1, 1]).v50_m_s == 315.0


def _separated(v: float) -> str:
    return f"{v},0,{int(v > 505)}\n"


@pytest.mark.parametrize(
    ("text", "flags", "named"),
    [
        ("".join(map(_separated, (480, 490, 500, 510, 520))), [], "no zone of mixed results"),
        ("480,0,0\n500,0,1\n510,0,0\n", [], "too few shots for a V50 fit"),
        ("480,0,0\n500,0,1\n510,0,0\n520,30,1\n", [], "give --by-obliquity"),
        ("480,0,0\n500,0,1\n510,0,0\n520,30,1\n", ["--by-obliquity"], "no obliquity gives"),
        ("480,0,0\n", ["--spread", "30"], "--spread: not an option of --method probit"),
        ("480,0,0\n", ["--method", "mil-std-662f", "--bootstrap", "9"], "--bootstrap: not an"),
        ("480,0,0\n", ["--confidence", "2"], "--confidence: confidence must be in"),
        ("480,0,0\n", ["--bootstrap", "many"], "--bootstrap must be a whole number"),
        ("480,0,0\n", ["--method", "mil-std-662f", "--count", "4"], "--count: count must"),
        ("480,0,0\n", ["--png", "/no/such/v50.png"], "--png"),
        ("480,0,0\n", ["--radius", "3"], "--preset is required"),
        ("480,0,0\n500,0,1\n", ["--method", "mil-std-662f"], "at least 2 partial and 2"),
    ],
)  # fmt: skip
def test_what_gives_no_v50_is_one_line_and_exit_2(text, flags, named, tmp_path, capsys,
                                                  monkeypatch):  # fmt: skip
    monkeypatch.chdir(tmp_path)
    path = tmp_path / "shots.csv"
    path.write_text(f"{HEADER}\n{text}")
    assert main(["v50", str(path), *flags]) == 2
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and err.startswith("plateimpact: error: ") and named in err
    assert [p.name for p in tmp_path.iterdir()] == ["shots.csv"]  # nothing written


GONOGO = Path(__file__).resolve().parents[1] / "studies" / "data" / "gonogo_SAE1010_1.47mm.csv"


def test_the_shipped_go_no_go_example_is_synthetic_and_centred_on_the_model():
    """Drawn from probit curves centred on the model's ballistic limits (σ = 15 m/s): each
    V50 interval holds the model's limit. At 0 deg the mixed results span only 32 m/s, so
    the profile likelihood of V10 stays within χ²₁(0.95) down to 1 m/s (the written-out
    −log L, minimised over σ with V10 fixed there): its interval has no lower end."""
    assert GONOGO.read_text().startswith("# SYNTHETIC DATA")
    shots = pi.Shots.from_csv(GONOGO)
    assert set(shots.notes) == {"synthetic"}
    groups = shots.groups_by_obliquity()
    limits = pi.limits.along_speed(
        pi.Simulation.from_names(), presets.DEFAULT_SPHERE, presets.plate("SAE1010/1.47"),
        list(groups), (50.0, 2000.0),
    )  # fmt: skip
    fits = [fit_v50(g.impact_speed, g.perforated, bootstrap=0) for g in groups.values()]
    for fit, line in zip(fits, limits.lines, strict=True):
        low, high = fit.v50_ci_m_s
        assert low < line.ballistic_limit < high
    normal = groups[0.0]
    v, y = normal.impact_speed, normal.perforated

    def nll(sigma: np.ndarray, v10: float = 1.0) -> np.ndarray:
        """At each σ of a column: the 4000 of the grid at once, not one call each."""
        z = (v - (v10 - sigma * stats.norm.ppf(0.1))) / sigma
        return -np.sum(np.where(y, stats.norm.logcdf(z), stats.norm.logcdf(-z)), axis=-1)

    profile = nll(np.geomspace(1.0, 1e4, 4000)[:, np.newaxis]).min()
    assert 2 * (profile + fits[0].log_likelihood) < stats.chi2.ppf(0.95, 1)
    assert fits[0].v10_ci_m_s[0] is None and fits[0].v10_ci_m_s[1] is not None


WEIGHTED = Path(__file__).resolve().parent / "data" / "v50_weighted_13_rows.csv"


def test_weighted_rows_are_counted_as_rounds_and_the_file_main_refused_is_fitted(capsys):
    """The 13-row file of 53 rounds (main refused it in this order, 'did not converge'):
    --json says rounds 53 and rows 13, shots the rounds (it said 13), perforations the
    perforating rounds; the text says both."""
    out = run_json(capsys, WEIGHTED, "--bootstrap", "30")
    shots = pi.Shots.from_csv(WEIGHTED)
    fit = fit_v50(shots.impact_speed, shots.perforated, shots.weight, bootstrap=30)
    assert (out["rounds"], out["rows"], out["shots"], out["perforations"]) == (53, 13, 53, 25)
    assert out["v50_m_s"] == fit.v50_m_s and out["bootstrap_failed"] == 0
    assert main(["v50", str(WEIGHTED), "--bootstrap", "0"]) == 0
    text = capsys.readouterr().out
    assert f"{WEIGHTED} at 0 deg: 53 shots (13 rows), 25 perforated; probit fit" in text
    assert main(["v50", str(WEIGHTED), "--bootstrap", "20"]) == 0
    assert "of the resamples 0 separated (sigma 0), 0 flat (no rise with speed), 0 failed" in (
        capsys.readouterr().out
    )


def test_a_weight_beyond_a_billion_is_one_line_and_exit_2(tmp_path, capsys):
    """Weights of 1e300 overflowed the bootstrap's counts (an internal error, a traceback
    file) and the sums; refused in one line with the range."""
    path = tmp_path / "huge.csv"
    rows = "".join(f"{v},0,{p},1e300\n" for v, p in ((480, 0), (500, 1), (510, 0), (520, 1)))
    path.write_text(f"{HEADER},weight\n{rows}")
    assert main(["v50", str(path), "--bootstrap", "10"]) == 2
    err = capsys.readouterr().err
    assert err == "plateimpact: error: weights must be in [0, 1e+09] (the shots a row stands for)\n"


def test_resamples_no_fit_converged_on_are_reported(capsys, monkeypatch):
    """Every resample's fit made to fail: the text counts them failed, left out; the
    bootstrap intervals are '-' (none), the JSON's bootstrap_failed the resamples."""

    def fails(shots, link, label):
        raise pi.V50Error(f"{label}: the {link.name} fit did not converge: injected")

    monkeypatch.setattr("plateimpact.v50.bootstrap.maximum", fails)
    assert main(["v50", str(WEIGHTED), "--bootstrap", "40"]) == 0
    text = capsys.readouterr().out
    out = run_json(capsys, WEIGHTED, "--bootstrap", "40")
    failed = out["bootstrap_failed"]
    assert failed == 40 - out["bootstrap_separated"] - out["bootstrap_flat"] > 30
    assert f"{failed} failed (no fit converged: left out)" in text
    assert out["sigma_bootstrap_ci_m_s"] is None
    sigma_line = next(line for line in text.splitlines() if line.startswith("  sigma"))
    assert sigma_line.endswith("]  -")  # the profile interval, then no bootstrap one


def test_more_fits_than_the_bound_are_refused_before_any_fit_unless_forced(
    shots_csv, capsys, monkeypatch
):
    """Two obliquities with 600,000 resamples each are 1,200,002 fits: refused in one
    line naming --bootstrap and --force before any fit (a fit would raise here)."""

    def no_fit(*args, **kwargs):
        raise AssertionError("a fit ran before the request was checked")

    monkeypatch.setattr("plateimpact.cli.commands.v50.fit_v50", no_fit)
    assert main(["v50", str(shots_csv), "--by-obliquity", "--bootstrap", "600000"]) == 2
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and "1,200,002 fits" in err and "--force" in err


def test_the_models_limit_scan_bound_names_the_flag_v50_has(shots_csv, capsys, monkeypatch):
    """With the scan bound lowered below what two lines need, v50 with a plate refuses in
    one line naming --force, which it takes; with --force the limits are found."""
    monkeypatch.setattr(pi.limits, "MAX_SCAN_SCENES", 10)
    args = ["v50", str(shots_csv), "--by-obliquity", "--bootstrap", "0", "--preset",
            "SAE1010/1.47"]  # fmt: skip
    assert main(args) == 2
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and "--force" in err
    assert main([*args, "--force", "--json"]) == 0
    out = json.loads(capsys.readouterr().out)
    assert all(row["model_ballistic_limit_m_s"] is not None for row in out)


def test_the_figure_names_the_file_not_its_path_and_keys_the_v50_line(
    shots_csv, tmp_path, monkeypatch
):
    from plateimpact.figures import v50_fits

    drawn_figures = []

    def keeping(*args, **kwargs):
        figure = original(*args, **kwargs)
        drawn_figures.append(figure)
        return figure

    original = v50_fits.v50_figure
    monkeypatch.setattr(v50_fits, "v50_figure", keeping)
    elsewhere = tmp_path / "deep" / "er"
    elsewhere.mkdir(parents=True)
    monkeypatch.chdir(elsewhere)  # the shots given by a path with ../ in it
    given = os.path.relpath(shots_csv, elsewhere)
    assert main(["v50", given, "--by-obliquity", "--bootstrap", "0", "--png", "f.png"]) == 0
    (figure,) = drawn_figures
    heading = figure._suptitle.get_text()
    assert heading.startswith(f"{shots_csv.name}: ") and ".." not in heading
    keyed = {text.get_text() for legend in figure.legends for text in legend.get_texts()}
    assert "V50" in keyed  # the dotted line at the V50, beside the fit and its interval
