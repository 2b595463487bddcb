"""Oblique shot data: the columns, what each shot says about perforation, the checks of
every row, round trips through CSV, per-shot spheres, and shots made by the model."""

from __future__ import annotations

import math

import numpy as np
import pytest

import plateimpact as pi
from plateimpact import presets
from plateimpact.units import deg, g, mm
from plateimpact_plugins import report

SPHERE = presets.DEFAULT_SPHERE
PLATE = presets.plate("2024-T3/1.27")
SIMULATION = pi.Simulation.from_names()
HEADER = "impact_speed_m_s,impact_obliquity_deg"

FIELDS = ("impact_speed", "impact_obliquity", "residual_speed", "exit_obliquity", "outcome")
EXTRA = ("perforated", "radius", "mass", "weight")


def assert_same_shots(a: pi.Shots, b: pi.Shots) -> None:
    for name in FIELDS + EXTRA:
        np.testing.assert_array_equal(getattr(a, name), getattr(b, name), err_msg=name)
    assert a.notes == b.notes


def test_each_column_that_says_whether_a_shot_perforated_is_enough_alone():
    text = (
        f"{HEADER},outcome,perforated,residual_speed_m_s\n"
        "300,45,ricochet,,\n"  # the outcome alone
        "400,45,,1,\n"  # go/no-go
        "420,45,,0,\n"
        "500,45,,,120\n"  # a residual speed alone, as in normal-incidence files
        "510,45,,,0\n"
        "600,45,perforation,1,250\n"  # all three, agreeing
        "350,45,ricochet,0,80\n"  # a ricochet's exit speed
    )
    shots = pi.Shots.from_csv_text(text)
    assert list(shots.perforated) == [False, True, False, True, False, True, False]
    assert list(shots.outcome) == [1, 0, 0, 0, 0, 3, 1]
    np.testing.assert_array_equal(
        shots.residual_speed, [math.nan, math.nan, math.nan, 120, 0, 250, 80]
    )
    assert list(shots.weight) == [1.0] * 7 and shots.notes == ("",) * 7
    assert np.isnan(shots.radius).all() and np.isnan(shots.mass).all()


def test_per_shot_sphere_weight_and_notes_in_user_units():
    text = (
        f"{HEADER},perforated,radius_mm,mass_g,weight,source,exit_obliquity_deg\n"
        "300,30,1,2.5,0.5,0.25,range A shot 17,20\n"
        "310,30,0,,,,,\n"
    )
    shots = pi.Shots.from_csv_text(text)
    assert shots.radius[0] == 2.5 * mm and shots.mass[0] == 0.5 * g
    assert np.isnan(shots.radius[1]) and np.isnan(shots.mass[1])
    assert list(shots.weight) == [0.25, 1.0] and shots.notes == ("range A shot 17", "")
    assert shots.exit_obliquity[0] == 20 * deg and shots.impact_obliquity[0] == 30 * deg


def test_byte_order_mark_and_crlf_read_like_plain_text(tmp_path):
    plain = f"# a comment\n{HEADER},outcome\n300,45,ricochet\n\n700,60,perforation\n"
    path = tmp_path / "windows.csv"
    path.write_bytes(b"\xef\xbb\xbf" + plain.replace("\n", "\r\n").encode())
    from_file, from_text = pi.Shots.from_csv(path), pi.Shots.from_csv_text(plain)
    assert_same_shots(from_file, from_text)
    assert from_file.labels == (f"{path} line 3", f"{path} line 5")


def test_csv_round_trip_is_exact_for_every_column():
    rng = np.random.default_rng(3)
    made = pi.synthetic_oblique_shots(
        SIMULATION,
        SPHERE,
        PLATE,
        np.linspace(100.0, 400.0, 12),
        np.repeat([0.0, 30.0, 60.0], 4) * deg,
        rng,
        speed_noise=3.0,
        residual_noise=0.03,
        exit_obliquity_noise=0.5 * deg,
        go_no_go_fraction=0.3,
    )
    n = len(made)
    shots = pi.Shots(
        *(getattr(made, name) for name in FIELDS),
        made.labels,
        perforated=made.perforated,
        radius=np.where(np.arange(n) % 2 == 0, 3.0 * mm, np.nan),
        mass=np.where(np.arange(n) % 3 == 0, 1.1 * g, np.nan),
        weight=np.linspace(0.0, 2.0, n),
        notes=tuple(f"note, {i}" if i % 4 else "" for i in range(n)),
    )
    assert (shots.outcome == 0).any() and (shots.outcome != 0).any()  # both kinds present
    text = shots.to_csv_text(["made for a test"])
    assert text.startswith("# made for a test\n")
    assert_same_shots(pi.Shots.from_csv_text(text), shots)


def test_default_columns_are_left_out_and_normal_incidence_files_keep_their_form():
    shots = pi.Shots.from_csv_text(f"{HEADER},residual_speed_m_s\n500,0,300\n300,0,0\n")
    header = shots.to_csv_text().splitlines()[0]
    assert header == "impact_speed_m_s,impact_obliquity_deg,residual_speed_m_s"
    assert list(shots.perforated) == [True, False]


#: (columns after the two impact columns, rows, what the one-line message must say)
BAD_ROWS = [
    ("", "500,0", "missing column residual_speed_m_s, perforated or outcome"),
    ("outcome,perforated", "500,30,,", "column outcome: each shot must say"),
    (
        "outcome,residual_speed_m_s",
        "500,30,embedment,40",
        "embedment contradicts residual speed 40",
    ),
    ("outcome,perforated", "500,30,ricochet,1", "perforated: '1' contradicts outcome ricochet"),
    ("perforated,residual_speed_m_s", "500,30,0,40", "perforated 0 contradicts residual speed 40"),
    ("perforated,residual_speed_m_s", "500,30,1,0", "perforated 1 contradicts residual speed 0"),
    ("outcome,residual_speed_m_s", "500,30,perforation,0", "perforation contradicts residual"),
    ("perforated", "500,30,yes", "column perforated: must be 1 or 0"),
    ("outcome", "500,30,bounced", "column outcome: must be one of ricochet"),
    ("perforated,weight", "500,30,1,-1", "column weight: must be >= 0, got '-1'"),
    ("perforated,weight", "500,30,1,inf", "column weight: must be finite"),
    ("perforated,radius_mm", "500,30,1,0", "column radius_mm: must be in [0.001, 1000] mm"),
    ("perforated,mass_g", "500,30,1,1e12", "column mass_g: must be in"),
    ("perforated,exit_obliquity_deg", "500,30,1,200", "exit_obliquity_deg: must be in [0, 180]"),
    ("perforated", "500,90,1", "column impact_obliquity_deg: must be in [0, 90)"),
    ("perforated", "500,30,1\n0,30,1\nx,30,0", "line 3, column impact_speed_m_s: must be in"),
    ("perforated", "500,30,1\n0,30,1\nx,30,0", "got '0' (and 1 more bad rows)"),
    ("perforated,perforated", "500,30,1,1", "column perforated appears more than once"),
]


@pytest.mark.parametrize(("columns", "rows", "named"), BAD_ROWS)
def test_bad_rows_are_one_line_naming_file_line_column_and_value(columns, rows, named):
    header = f"{HEADER},{columns}" if columns else HEADER
    with pytest.raises(pi.ShotDataError) as caught:
        pi.Shots.from_csv_text(f"{header}\n{rows}\n", source="s.csv")
    message = str(caught.value)
    assert "\n" not in message and message.startswith("s.csv line ")
    assert named in message


def test_from_columns_checks_like_csv_and_names_the_row():
    shots = pi.Shots.from_columns(
        {"impact_speed_m_s": [300, "400"], "impact_obliquity_deg": [45, 45], "perforated": [0, 1.0]}
    )
    assert list(shots.perforated) == [False, True] and np.isnan(shots.residual_speed).all()
    with pytest.raises(pi.ShotDataError, match=r"^shots row 1, column outcome: must be one of"):
        pi.Shots.from_columns(
            {
                "impact_speed_m_s": [300, 400],
                "impact_obliquity_deg": [0, 0],
                "outcome": ["ricochet", "x"],
            }
        )


def test_scenes_use_each_shots_own_sphere_and_refuse_impossible_densities():
    shots = pi.Shots.from_csv_text(
        f"{HEADER},perforated,radius_mm,mass_g\n300,30,1,4,\n400,45,0,,2\n500,60,1,,\n",
        source="s.csv",
    )
    batch = shots.scenes(SPHERE, PLATE)
    np.testing.assert_array_equal(batch.radius, [4 * mm, SPHERE.radius, SPHERE.radius])
    np.testing.assert_array_equal(batch.mass, [SPHERE.mass, 2 * g, SPHERE.mass])
    np.testing.assert_array_equal(batch.impact_obliquity, shots.impact_obliquity)
    assert batch.a[0] == PLATE.a and batch.thickness[2] == PLATE.thickness
    heavy = pi.Shots.from_csv_text(
        f"{HEADER},perforated,mass_g\n300,30,1,\n400,45,0,500\n", source="s.csv"
    )
    with pytest.raises(pi.ShotDataError, match=r"^s.csv line 3: mass .* density"):
        heavy.scenes(SPHERE, PLATE)


def test_groups_by_obliquity_partition_the_shots_in_increasing_obliquity():
    shots = pi.Shots.from_csv_text(f"{HEADER},perforated\n1,60,0\n2,0,1\n3,60,1\n4,30,0\n5,0,0\n")
    groups = shots.groups_by_obliquity()
    assert list(groups) == [0.0, 30 * deg, 60 * deg]
    assert [list(group.impact_speed) for group in groups.values()] == [[2, 5], [4], [1, 3]]
    assert [list(group.perforated) for group in groups.values()] == [
        [True, False],
        [False],
        [False, True],
    ]


def test_noise_free_synthetic_shots_are_the_models_own_results():
    speeds, obliquities = np.array([150.0, 210.0, 400.0]), np.array([0.0, 45.0, 60.0]) * deg
    shots = pi.synthetic_oblique_shots(SIMULATION, SPHERE, PLATE, speeds, obliquities)
    result = SIMULATION.run_batch(
        [pi.Scene(SPHERE, PLATE, v, o) for v, o in zip(speeds, obliquities, strict=True)]
    )
    exits = result.outcome != pi.Outcome.EMBEDMENT
    np.testing.assert_array_equal(shots.impact_speed, speeds)
    np.testing.assert_array_equal(shots.outcome, result.outcome)
    np.testing.assert_array_equal(shots.residual_speed, np.where(exits, result.exit_speed, 0.0))
    np.testing.assert_array_equal(shots.perforated, result.outcome == pi.Outcome.PERFORATION)
    # Only go/no-go: the outcome, residual speed and exit obliquity are not recorded.
    blind = pi.synthetic_oblique_shots(
        SIMULATION, SPHERE, PLATE, speeds, obliquities, go_no_go_fraction=1.0
    )
    assert (blind.outcome == 0).all() and np.isnan(blind.residual_speed).all()
    np.testing.assert_array_equal(blind.perforated, shots.perforated)


def test_calibration_uses_only_normal_shots_with_a_residual_speed():
    normal = pi.Shots.from_csv_text(
        f"{HEADER},residual_speed_m_s,perforated\n300,0,0,\n500,0,,1\n600,0,400,\n700,0,500,\n"
    )
    assert list(normal.perforated) == [False, True, True, True]
    with pytest.raises(pi.ShotDataError, match="2 perforating shots at normal incidence"):
        report.newton_fit(normal, presets.plate("2024-T3/3.18"))


def test_the_fits_of_a_and_b_refuse_per_shot_spheres_and_weights_rather_than_ignore_them():
    rows = "300,0,0,{}\n500,0,300,\n700,0,500,\n900,0,700,\n"
    for column, value in (("radius_mm", "3"), ("mass_g", "1"), ("weight", "2")):
        shots = pi.Shots.from_csv_text(
            f"{HEADER},residual_speed_m_s,{column}\n" + rows.format(value), source="s.csv"
        )
        with pytest.raises(pi.ShotDataError, match=r"^s.csv line 2: the fits of a and b take"):
            report.newton_fit(shots, presets.plate("2024-T3/3.18"))


def test_shots_built_in_python_need_one_entry_per_shot():
    with pytest.raises(pi.ShotDataError, match=r"2 impact speeds but \{'outcome': 3\}"):
        pi.Shots(np.ones(2), np.zeros(2), np.zeros(2), np.zeros(2), np.ones(3, int), ("a", "b"))
