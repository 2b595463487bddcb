"""The model against measured shots (``plateimpact validate``): shots made by the model
itself agree exactly; shots made at another P* disagree exactly where the two models'
outcomes differ, each near a boundary; scores follow their closed forms; bad input is
one line and exit code 2."""

from __future__ import annotations

import functools
import json
import math
from pathlib import Path

import attrs
import numpy as np
import pytest

import plateimpact as pi
from plateimpact import presets
from plateimpact.cli import main
from plateimpact.limits import along_speed
from plateimpact.units import deg, mm

SPHERE = presets.DEFAULT_SPHERE
PLATE = presets.plate("2024-T3/1.27")
#: The same plate failing 30% deeper: its boundaries move by tens of m/s.
DEEPER = PLATE.with_constants(critical_penetration=1.3 * PLATE.critical_penetration)
SIMULATION = pi.Simulation.from_names()
OBLIQUITIES = np.array([0.0, 45.0, 60.0]) * deg
IMPACT = "impact_speed_m_s,impact_obliquity_deg"
SPEEDS = np.linspace(103.0, 403.0, 16)  # [m/s]; none within 0.1 m/s of a boundary (checked)


@functools.cache
def shots_of(plate: pi.Plate, go_no_go: float = 0.25) -> pi.Shots:
    """Noise-free shots of ``plate``: every speed at every obliquity, some go/no-go."""
    return pi.synthetic_oblique_shots(
        SIMULATION, SPHERE, plate, np.tile(SPEEDS, OBLIQUITIES.size),
        np.repeat(OBLIQUITIES, SPEEDS.size), np.random.default_rng(5),
        go_no_go_fraction=go_no_go,
    )  # fmt: skip


@functools.cache
def report_on(plate: pi.Plate) -> pi.ValidationReport:
    return pi.validate(SIMULATION, SPHERE, PLATE, shots_of(plate))


def test_shots_made_by_the_model_agree_exactly():
    report, shots = report_on(PLATE), shots_of(PLATE)
    assert (shots.outcome == 0).sum() >= 5 and (shots.outcome != 0).sum() >= 20
    assert report.agreement == 1.0 and report.agrees.all() and report.disagreements == ()
    assert report.residual_speed_rms == 0.0 and report.residual_speed_bias == 0.0
    assert report.exit_obliquity_rms == 0.0
    paired = np.isfinite(report.residual_speed_error)
    assert paired.sum() >= 15  # perforations and ricochets, both compared
    assert set(shots.outcome[paired]) == {pi.Outcome.RICOCHET, pi.Outcome.PERFORATION}
    for measured, row in report.confusion.items():
        for predicted, count in row.items():
            if measured != predicted and measured in row:  # an outcome: only the diagonal
                assert count == 0
    assert sum(sum(row.values()) for row in report.confusion.values()) == len(shots)
    assert (
        sum(report.confusion["not perforated"].values())
        == ((shots.outcome == 0) & ~shots.perforated).sum()
    )


def outcome_at(line, speed: float, go_no_go: bool):
    """The outcome (or, for go/no-go, whether it perforates) of the band holding ``speed``."""
    (band,) = [b for b in line.bands if b.start <= speed < b.end]
    outcome = band.regime.outcome
    return outcome is pi.Outcome.PERFORATION if go_no_go else outcome


def test_shots_at_another_pstar_disagree_exactly_between_the_two_models_boundaries():
    report, shots = report_on(DEEPER), shots_of(DEEPER)
    # The oracle: both models' bands, located by the boundary finder, not by the runs.
    ours, theirs = (
        along_speed(SIMULATION, SPHERE, plate, OBLIQUITIES, report.speeds)
        for plate in (PLATE, DEEPER)
    )
    expected = set()
    for i in range(len(shots)):
        k = int(np.flatnonzero(OBLIQUITIES == shots.impact_obliquity[i])[0])
        v, go_no_go = shots.impact_speed[i], shots.outcome[i] == 0
        for line in (ours.lines[k], theirs.lines[k]):
            assert all(abs(v - b.at) > 0.1 for b in line.boundaries)
        if outcome_at(ours.lines[k], v, go_no_go) != outcome_at(theirs.lines[k], v, go_no_go):
            expected.add(shots.labels[i])
    found = {d.label for d in report.disagreements}
    assert found == expected and 4 <= len(found) < len(shots) // 2
    assert report.agreement == pytest.approx(1 - len(found) / len(shots))
    span = SPEEDS[-1] - SPEEDS[0]
    for d in report.disagreements:
        assert d.distance is not None and d.distance < 0.2 * span
        assert_nearest_change(d)


def assert_nearest_change(d) -> None:
    """Direct runs of our model: no speed nearer than the reported distance gives what
    was measured (the outcome, or perforation for a go/no-go shot), and a speed just
    beyond the reported boundary does."""
    go_no_go = d.measured in ("perforated", "not perforated")
    near = np.linspace(d.impact_speed - d.distance + 0.05, d.impact_speed + d.distance - 0.05, 200)
    beyond = d.boundary + 0.05 * np.sign(d.boundary - d.impact_speed)
    speeds = np.append(near, [beyond, d.impact_speed])
    everything = SIMULATION.run_batch(
        pi.SceneBatch.grid(SPHERE, PLATE, speeds, [d.impact_obliquity])
    )
    assert pi.Outcome(int(everything.outcome[-1])).label == d.predicted  # at the shot's speed
    result = everything.take(np.arange(speeds.size - 1))
    if go_no_go:
        agrees = (result.outcome == pi.Outcome.PERFORATION) == (d.measured == "perforated")
    else:
        agrees = np.array([pi.Outcome(int(o)).label == d.measured for o in result.outcome])
    assert not agrees[:-1].any() and agrees[-1]


def test_the_boundary_is_the_nearest_beyond_which_the_model_gives_what_was_measured():
    # At 45 deg the plate fails at 184.6 m/s (ricochet after failure: the same outcome),
    # the sphere embeds from 206.0 and perforates from 208.75 m/s: a perforation measured
    # at 190 m/s is 18.75 m/s from agreeing, not 16 (embedment would not agree either).
    text = (
        "impact_speed_m_s,impact_obliquity_deg,outcome,perforated\n190,45,perforation,\n190,45,,1\n"
    )
    report = pi.validate(SIMULATION, SPHERE, PLATE, pi.Shots.from_csv_text(text))
    outcome, go_no_go = report.disagreements
    assert outcome.boundary == pytest.approx(208.75, abs=0.1)
    assert go_no_go.boundary == pytest.approx(208.75, abs=0.1)
    embedded = pi.Shots.from_csv_text(
        "impact_speed_m_s,impact_obliquity_deg,outcome\n190,45,embedment\n"
    )
    (d,) = pi.validate(SIMULATION, SPHERE, PLATE, embedded).disagreements
    assert d.boundary == pytest.approx(206.0, abs=0.1)  # the embedment band's near edge
    assert_nearest_change(d)
    for d in report.disagreements:
        assert_nearest_change(d)


def test_agreement_and_errors_follow_their_weighted_closed_forms():
    shots, wrong = shots_of(DEEPER), ~report_on(DEEPER).agrees
    weight = np.where(wrong, 3.0, 0.5)
    weighted = pi.validate(  # a coarse boundary search: only the agreement is checked
        SIMULATION, SPHERE, PLATE, attrs.evolve(shots, weight=weight), resolution=10.0,
        tolerance=1.0,
    )  # fmt: skip
    share = 0.5 * (~wrong).sum() / (0.5 * (~wrong).sum() + 3.0 * wrong.sum())
    assert weighted.agreement == pytest.approx(share, rel=1e-12)
    shots = shots_of(PLATE, go_no_go=0.0)
    # Our own shots with every measured exit 4 m/s slower and 2 deg steeper.
    moved = attrs.evolve(
        shots,
        residual_speed=np.where(shots.residual_speed > 0, shots.residual_speed - 4.0, 0.0),
        exit_obliquity=shots.exit_obliquity + 2.0 * deg,
    )
    own = pi.validate(SIMULATION, SPHERE, PLATE, moved)
    assert own.agreement == 1.0
    assert own.residual_speed_rms == pytest.approx(4.0, rel=1e-9)
    assert own.residual_speed_bias == pytest.approx(4.0, rel=1e-9)  # model - measured
    assert own.exit_obliquity_rms == pytest.approx(2.0 * deg, rel=1e-9)


def no_constant(constant: str) -> float:
    raise AssertionError(f"{constant} is not strict JSON")


def test_go_no_go_shots_alone_give_null_errors_in_json():
    blind = shots_of(PLATE, go_no_go=1.0).take(np.arange(0, 48, 6))
    out = pi.validate(SIMULATION, SPHERE, PLATE, blind).to_json()
    text = json.dumps(out)
    json.loads(text, parse_constant=no_constant)  # strict JSON: no NaN, no Infinity
    assert out["residual_speed_rms_m_s"] is None and out["residual_speed_bias_m_s"] is None
    assert out["exit_obliquity_rms_deg"] is None and out["outcome_agreement"] == 1.0
    assert '"perforated"' in text and out["shots"] == 8


def test_a_shots_own_sphere_is_the_one_run_and_searched():
    # A 2-mm sphere of the default's density: lighter, so it perforates later.
    text = (
        "impact_speed_m_s,impact_obliquity_deg,perforated,radius_mm,mass_g\n"
        f"190,0,1,2,{SPHERE.density * 4 / 3 * math.pi * 8e-9 / 1e-3!r}\n"
        "150,0,1,,\n"
    )
    shots = pi.Shots.from_csv_text(text)
    report = pi.validate(SIMULATION, SPHERE, PLATE, shots)
    assert not report.agrees.any() and len(report.limits) == 2
    small = pi.Sphere(radius=2 * mm, mass=float(shots.mass[0]))
    limit = along_speed(SIMULATION, small, PLATE, [0.0], report.speeds).lines[0].ballistic_limit
    assert report.disagreements[0].boundary == pytest.approx(limit, abs=0.01)
    assert limit > 190 > report.disagreements[1].boundary


# ------------------------------------------------------------------------- the command


def test_the_figure_has_a_panel_per_obliquity_to_the_nearest_degree():
    from plateimpact.figures.validation_panels import MAX_PANELS, validation_figure

    text = f"{IMPACT},perforated\n200,44.6,0\n300,45.3,1\n250,60,0\n"
    report = pi.validate(SIMULATION, SPHERE, PLATE, pi.Shots.from_csv_text(text))
    figure = validation_figure(report, SIMULATION, points=20)
    titles = [ax.get_title() for ax in figure.axes if ax.get_title()]
    assert titles == ["45°", "60°"] and len(figure.axes) == 6  # three axes a panel
    model = SIMULATION.model  # the figure says which model its curves are
    assert (f"model: {model.resistance.name} + {model.failure.name}, "
            f"{SIMULATION.integrator.name}") in figure._suptitle.get_text()  # fmt: skip
    many = "".join(f"300,{k},1\n" for k in range(MAX_PANELS + 1))
    with pytest.raises(pi.ShotDataError, match=f"shots at {MAX_PANELS + 1} obliquities"):
        validation_figure(
            attrs.evolve(report, shots=pi.Shots.from_csv_text(f"{IMPACT},perforated\n{many}")),
            SIMULATION,
        )


@pytest.fixture(scope="module")
def deeper_csv(tmp_path_factory):
    path = tmp_path_factory.mktemp("shots") / "deeper.csv"
    path.write_text(shots_of(DEEPER).to_csv_text(["made at P* x 1.3"]))
    return path


def test_validate_json_names_every_score(deeper_csv, capsys):
    assert main(["validate", str(deeper_csv), "--preset", "2024-T3/1.27", "--json"]) == 0
    out = json.loads(capsys.readouterr().out)
    report = report_on(DEEPER)
    assert out["outcome_agreement"] == report.agreement and out["shots"] == 48
    assert out["confusion"] == report.confusion
    assert len(out["disagreements"]) == len(report.disagreements)
    first = out["disagreements"][0]
    assert set(first) >= {
        "label", "impact_speed_m_s", "impact_obliquity_deg", "measured", "predicted",
        "distance_to_boundary_m_s",
    }  # fmt: skip
    assert first["label"].startswith(f"{deeper_csv} line ")
    for key in ("residual_speed_rms_m_s", "residual_speed_bias_m_s", "exit_obliquity_rms_deg"):
        assert isinstance(out[key], float)
    assert out["plate"]["material"] == "2024-T3" and out["sphere"]["radius_mm"] == 3.175
    assert out["model"]["failure"] == "plugging"


def test_validate_text_and_figure(tmp_path, capsys):
    few = tmp_path / "few.csv"  # every third shot: a figure of three columns still
    few.write_text(shots_of(DEEPER).take(np.arange(0, 48, 3)).to_csv_text())
    png = tmp_path / "validate.png"
    args = ["validate", str(few), "--preset", "2024-T3/1.27", "--png", str(png)]
    assert main(args) == 0
    out = capsys.readouterr().out
    assert "outcome agreement" in out and "shots disagree" in out and f"figure: {png}" in out
    assert png.read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"


@pytest.mark.parametrize(
    ("text", "flags", "named"),
    [
        (f"{IMPACT}\n300,0\n", [], "missing column"),
        (f"{IMPACT},outcome\n300,0,hit\n", [], "line 2, column outcome"),
        (f"{IMPACT},perforated,weight\n300,0,1,0\n", [], "every shot has weight 0"),
        (f"{IMPACT},perforated\n300,0,1\n", ["--pstar", "-1"], "--pstar"),
        (f"{IMPACT},perforated\n300,0,1\n", ["--png", "/no/such/x.png"], "--png"),
        (f"{IMPACT},perforated\n300,0,1\n", ["--radius", "0"], "--radius"),
        (
            f"{IMPACT},perforated\n" + "".join(f"300,{k},1\n" for k in range(17)),
            ["--png", "x.png"],
            "shots at 17 obliquities",
        ),
    ],
)  # fmt: skip
def test_bad_shots_and_options_are_one_line_and_exit_2(
    text, flags, named, tmp_path, capsys, monkeypatch
):
    monkeypatch.chdir(tmp_path)
    path = tmp_path / "shots.csv"
    path.write_text(text)
    assert main(["validate", str(path), "--preset", "2024-T3/1.27", *flags]) == 2
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and err.startswith("plateimpact: error: ") and named in err
    assert [p.name for p in tmp_path.iterdir()] == ["shots.csv"]  # nothing written


def test_the_shipped_oblique_examples_are_synthetic_and_agree_with_the_model_that_made_them():
    data = Path(__file__).resolve().parents[1] / "studies" / "data"
    files = sorted(data.glob("oblique_SAE1010_1.47mm_*.csv"))
    assert [f.name for f in files] == [
        "oblique_SAE1010_1.47mm_pstar4.6.csv",
        "oblique_SAE1010_1.47mm_variable_pstar.csv",
    ]
    for path in files:
        shots = pi.Shots.from_csv(path)
        assert path.read_text().startswith("# SYNTHETIC DATA") and set(shots.notes) == {"synthetic"}
        assert len(shots.groups_by_obliquity()) == 4 and (shots.outcome == 0).any()
    variable = pi.Simulation.from_names(failure="variable-pstar")
    report = pi.validate(
        variable, SPHERE, presets.plate("SAE1010/1.47"), pi.Shots.from_csv(files[1])
    )
    # Noise of 3 m/s on impact speeds moves few shots across a boundary; 3% on residual
    # speeds of a few hundred m/s gives an RMS of about 10 m/s.
    assert report.agreement >= 0.95
    paired = np.isfinite(report.residual_speed_error)
    measured = report.shots.residual_speed[paired]
    assert report.residual_speed_rms < 0.06 * np.sqrt(np.mean(measured**2))
