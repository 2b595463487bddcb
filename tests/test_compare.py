"""Two runs compared: outcome changes collapsed into ranges per plate and obliquity (or
speed), against a table written by hand and a brute-force oracle; the ``compare``
command's text, ``--summary``, ``--json`` and ``--png`` (docs/archive.md)."""

from __future__ import annotations

import itertools
import json
import math
import re
from collections import defaultdict
from pathlib import Path

import numpy as np
import pytest
from test_output_files import assert_one_line, run_cli

import plateimpact as pi
from plateimpact import presets
from plateimpact.model.results import RESULT_FIELDS

ROOT = Path(__file__).resolve().parents[1]
SPHERE = presets.DEFAULT_SPHERE
#: Regimes by short name: (outcome code, plate failed), and their names as written out.
REGIMES = {"R": (1, False), "Rf": (1, True), "E": (2, False), "Ef": (2, True), "P": (3, True)}
NAMES = {
    (1, False): "ricochet",
    (1, True): "ricochet after failure",
    (2, False): "embedment",
    (2, True): "embedment after failure",
    (3, True): "perforation",
}

# Scenes by hand: (regime A, regime B, exit speed A, B [m/s], exit obliquity A, B [deg]).
# Embedments have exit speed 0 and an obliquity at rest, which is never compared.
ROW_30 = [  # 2024-T3/3.18 at 30 deg, 100 ... 1000 m/s
    ("P", "E", 50, 0, 20, 25),  # a change at the first scene ...
    ("P", "E", 120, 0, 22, 28),
    ("R", "R", 40, 43, 150, 152),
    ("R", "R", 60, 54, 140, 141),
    ("E", "R", 0, 80, 30, 130),
    ("Ef", "Ef", 0, 0, 40, 10),  # both at rest: 30 deg apart, not an exit difference
    ("P", "R", 300, 90, 20, 150),
    ("P", "R", 350, 100, 25, 140),
    ("R", "E", 70, 0, 120, 60),
    ("P", "E", 400, 0, 30, 35),  # ... and the same change again at the last
]
ROW_60 = [  # 2024-T3/3.18 at 60 deg: only the plate's state changes
    ("R", "R", 30, 30, 100, 100),
    ("Rf", "R", 35, 45, 110, 112),
    ("Rf", "R", 40, 52, 115, 118),
] + [("R", "R", 50, 50, 120, 120)] * 7
SWEEP = [  # SAE1010/1.47 at 500 m/s, 0 ... 80 deg: an obliquity sweep
    ("P", "P", 100, 100, 0, 0),
    ("P", "R", 100, 50, 10, 160),
    ("R", "R", 80, 80, 170, 170),
    ("R", "R", 90, 90, 175, 175),
    ("R", "R", 95, 95, 178, 178),
]
# What the comparison must find, worked out by hand from the tables above:
# (from, to [m/s or deg], change, scenes, max |Δ exit speed| [m/s], max |Δ exit obliquity| [deg])
EXPECTED = {
    ("2024-T3/3.18", 30.0): [
        (100, 200, "perforation -> embedment", 2, 120, None),
        (500, 500, "embedment -> ricochet", 1, 80, None),
        (700, 800, "perforation -> ricochet", 2, 250, 130),
        (900, 900, "ricochet -> embedment", 1, 70, None),
        (1000, 1000, "perforation -> embedment", 1, 400, None),
    ],
    ("2024-T3/3.18", 60.0): [(200, 300, "ricochet after failure -> ricochet", 2, 12, 3)],
    ("SAE1010/1.47", 500.0): [(20, 20, "perforation -> ricochet", 1, 50, 150)],
}
# Where the regimes agree: (scenes, max |Δ exit speed|, max |Δ exit obliquity|)
EXPECTED_SAME = {
    ("2024-T3/3.18", 30.0): (3, 6, 2),
    ("2024-T3/3.18", 60.0): (8, 0, 0),
    ("SAE1010/1.47", 500.0): (4, 0, 0),
}


def batch_result(outcome, failed, exit_speed, exit_obliquity) -> pi.BatchResult:
    n = len(outcome)
    columns = {name: np.full(n, 1e-3) for name in RESULT_FIELDS}
    columns["outcome"] = np.asarray(outcome, dtype=np.int8)
    columns["plate_failed"] = np.asarray(failed, dtype=bool)
    columns["exit_speed"] = np.asarray(exit_speed, dtype=float)
    columns["exit_obliquity"] = np.asarray(exit_obliquity, dtype=float)
    return pi.BatchResult(columns)


def hand_made() -> pi.StudyResults:
    """The three tables as one study, its scenes in a shuffled order."""
    rows = []
    for speed, entry in zip(range(100, 1001, 100), ROW_30, strict=True):
        rows.append(("2024-T3/3.18", speed, 30.0, entry))
    for speed, entry in zip(range(100, 1001, 100), ROW_60, strict=True):
        rows.append(("2024-T3/3.18", speed, 60.0, entry))
    for obliquity, entry in zip(range(0, 81, 20), SWEEP, strict=True):
        rows.append(("SAE1010/1.47", 500.0, float(obliquity), entry))
    rows = [rows[k] for k in np.random.default_rng(7).permutation(len(rows))]
    scenes = [
        pi.Scene(SPHERE, presets.plate(plate), float(v), math.radians(ob))
        for plate, v, ob, _ in rows
    ]
    study = pi.Study.from_scenes("hand", scenes, [pi.Variant("a"), pi.Variant("b")])
    runs = {}
    for name, k in (("a", 0), ("b", 1)):
        regimes = [REGIMES[entry[k]] for *_, entry in rows]
        runs[name] = batch_result(
            [r[0] for r in regimes],
            [r[1] for r in regimes],
            [entry[2 + k] for *_, entry in rows],
            [math.radians(entry[4 + k]) for *_, entry in rows],
        )
    return pi.StudyResults(study, runs)


def user(axis: str, value: float) -> float:
    return math.degrees(value) if axis == "impact_obliquity" else value


def test_ranges_are_the_ones_worked_out_by_hand():
    comparison = hand_made().compare("a", "b")
    found = defaultdict(list)
    for r in comparison.ranges():
        fixed = math.degrees(r.fixed) if r.axis == "impact_speed" else r.fixed
        obliquity = r.spread.max_abs_exit_obliquity_change
        found[(r.plate, round(fixed, 9))].append(
            (
                pytest.approx(user(r.axis, r.start)),
                pytest.approx(user(r.axis, r.end)),
                r.pair,
                r.spread.scenes,
                pytest.approx(r.spread.max_abs_exit_speed_change),
                None if obliquity is None else pytest.approx(math.degrees(obliquity)),
            )
        )
    assert dict(found) == EXPECTED
    sweep = [row for row in comparison.rows() if row.plate == "SAE1010/1.47"]
    assert [row.axis for row in sweep] == ["impact_obliquity"]
    for row in comparison.rows():
        fixed = math.degrees(row.fixed) if row.axis == "impact_speed" else row.fixed
        scenes, speed, obliquity = EXPECTED_SAME[(row.plate, round(fixed, 9))]
        assert row.same.scenes == scenes
        assert row.same.max_abs_exit_speed_change == pytest.approx(speed)
        assert math.degrees(row.same.max_abs_exit_obliquity_change) == pytest.approx(obliquity)


def test_an_embedment_gives_no_nan_and_no_exit_obliquity_difference():
    comparison = hand_made().compare("a", "b")
    embedded = (comparison.outcome_a == 2) | (comparison.outcome_b == 2)
    assert embedded.any() and not embedded.all()
    change = comparison.exit_obliquity_change
    np.testing.assert_array_equal(np.ma.getmaskarray(change), embedded)
    assert np.all(np.isfinite(change.data)) and np.all(np.isfinite(comparison.exit_speed_change))
    found = json.loads(json.dumps(comparison.to_json(), allow_nan=False))  # NaN: ValueError
    turned = {
        (r["outcome_a"], r["outcome_b"], r.get("from_m_s", r.get("from_deg"))): r[
            "max_abs_delta_exit_obliquity_deg"
        ]
        for r in found["outcome_ranges"]
    }
    assert turned[("perforation", "embedment", 100.0)] is None  # B embeds
    assert turned[("embedment", "ricochet", 500.0)] is None  # A embeds
    assert turned[("perforation", "ricochet", 700.0)] == pytest.approx(130.0)


def regime_of(result: pi.BatchResult, i: int) -> tuple[int, bool]:
    return int(result.outcome[i]), bool(result.plate_failed[i])


def oracle(results: pi.StudyResults, a: str, b: str) -> dict[tuple[str, float], list[tuple]]:
    """Ranges along speed per (plate, obliquity), by a plain loop over sorted scenes."""
    study, ra, rb = results.study, results[a], results[b]
    speeds, obliquities = study.scenes.impact_speed, study.scenes.impact_obliquity
    rows = defaultdict(list)
    for i in range(len(ra)):
        rows[(study.plate_labels[i], round(math.degrees(obliquities[i]), 6))].append(i)
    found = {}
    for key, members in rows.items():
        members.sort(key=lambda i: speeds[i])
        ranges = []
        pairs = itertools.groupby(members, key=lambda i: (regime_of(ra, i), regime_of(rb, i)))
        for (one, other), group in pairs:
            group = list(group)
            if one == other:
                continue
            leave = [i for i in group if ra.outcome[i] != 2 and rb.outcome[i] != 2]
            speed = max(abs(rb.exit_speed[i] - ra.exit_speed[i]) for i in group)
            turns = [abs(rb.exit_obliquity[i] - ra.exit_obliquity[i]) for i in leave]
            ranges.append(
                (
                    speeds[group[0]],
                    speeds[group[-1]],
                    f"{NAMES[one]} -> {NAMES[other]}",
                    len(group),
                    pytest.approx(speed),
                    pytest.approx(math.degrees(max(turns))) if turns else None,
                )
            )
        found[key] = ranges
    return found


def from_json(found: dict) -> dict[tuple[str, float], list[tuple]]:
    out = defaultdict(list)
    for row in found["rows"]:
        out[(row["plate"], row["obliquity_deg"])] = []
    for r in found["outcome_ranges"]:
        out[(r["plate"], r["obliquity_deg"])].append(
            (
                r["from_m_s"],
                r["to_m_s"],
                f"{r['outcome_a']} -> {r['outcome_b']}",
                r["scenes"],
                r["max_abs_delta_exit_speed_m_s"],
                r["max_abs_delta_exit_obliquity_deg"],
            )
        )
    return dict(out)


def test_random_grids_agree_with_a_brute_force_oracle():
    rng = np.random.default_rng(11)
    codes = list(REGIMES.values())
    speeds = np.arange(100.0, 501.0, 10.0)
    study = pi.Study.grid(
        "r", ["2024-T3/3.18", "SAE1010/1.47"], [0, 30, 60], speeds, [pi.Variant("a")]
    )
    n = len(study.scenes)
    order = rng.permutation(n)  # the scenes in any order
    study = pi.Study(
        "r", study.scenes.take(order), study.variants, np.take(study.plate_labels, order)
    )
    for _ in range(5):
        runs = {}
        for name in ("a", "b"):
            # long runs of one regime, so that ranges are more than one scene wide
            steps = np.cumsum(rng.random(n) < 0.15)
            picked = [codes[k % len(codes)] for k in (steps + rng.integers(5)) % len(codes)]
            runs[name] = batch_result(
                [p[0] for p in picked],
                [p[1] for p in picked],
                np.where([p[0] == 2 for p in picked], 0.0, rng.uniform(0, 500, n)),
                rng.uniform(0, math.pi, n),
            )
        results = pi.StudyResults(study, runs)
        found = results.compare("a", "b").to_json()
        expected = oracle(results, "a", "b")
        assert from_json(json.loads(json.dumps(found, allow_nan=False))) == expected
        changed = sum(len(r) for r in expected.values())
        assert found["ranges"] == changed > 0
        counts: dict[str, int] = defaultdict(int)
        for ranges in expected.values():
            for r in ranges:
                counts[r[2]] += r[3]
        assert found["changes"] == counts
        assert found["changed_scenes"] == sum(counts.values())


def test_runs_of_other_sizes_are_refused():
    results = hand_made()
    short = results["b"].take(np.arange(3))
    with pytest.raises(pi.ParameterError, match="must cover the same 25 scenes"):
        pi.StudyResults(results.study, {"a": results["a"], "b": short}).compare("a", "b")


# -- the command, on the README's example ---------------------------------------------------


@pytest.fixture(scope="module")
def readme_archive(tmp_path_factory) -> tuple[Path, pi.StudyResults]:
    """The 3.18-mm family of Figures 25-31, as `plateimpact reproduce` archives it."""
    from plateimpact_studies.fig25_31_2024t3_3_18mm import study

    path = tmp_path_factory.mktemp("readme") / "report.h5"
    return path, study().run(archive=path)


README_RUNS = ["2024-T3_3.18mm/plugging", "large-pstar"]


def test_the_readme_example_prints_ranges_in_under_40_lines(readme_archive):
    path, results = readme_archive
    code, out, err = run_cli(["compare", str(path), *README_RUNS])
    assert code == 0, err
    lines = out.splitlines()
    assert len(lines) < 40
    expected = oracle(results, "plugging", "large-pstar")
    listed = [line for line in lines if re.match(r"  [\d.]+(-[\d.]+)? m/s \(", line)]
    assert len(listed) == sum(len(r) for r in expected.values()) > 4
    for (plate, obliquity), ranges in expected.items():
        head = next(
            k for k, line in enumerate(lines) if line.startswith(f"{plate} at {obliquity:g} deg")
        )
        for k, (start, end, pair, scenes, speed, _) in enumerate(ranges, start=1):
            where = f"{start:g}-{end:g} m/s" if start != end else f"{start:g} m/s"
            assert lines[head + k].startswith(f"  {where} ({scenes} scene"), lines[head + k]
            assert (
                f"{pair}; exit speed differs by up to {speed.expected:.1f} m/s" in lines[head + k]
            )


def test_the_readmes_quoted_output_is_what_compare_prints(readme_archive):
    path, _ = readme_archive
    readme = (ROOT / "README.md").read_text()
    block = readme.split(
        "$ plateimpact compare report/report.h5 2024-T3_3.18mm/plugging large-pstar\n"
    )[-1]
    quoted = block.split("```")[0].splitlines()
    quoted = list(itertools.takewhile(lambda line: not line.startswith("$ "), quoted))
    code, out, _ = run_cli(["compare", str(path), *README_RUNS])
    lines = out.splitlines()
    shown = [line for line in quoted if line.strip() != "..."]
    assert f"({len(lines)} lines here" in readme
    assert len(shown) >= 4
    at = 0
    for line in shown:  # each quoted line printed, in order
        assert line in lines[at:], line
        at = lines.index(line, at) + 1


def test_json_is_one_object_with_units_in_its_keys(readme_archive, tmp_path):
    path, results = readme_archive
    png = tmp_path / "c.png"
    code, out, err = run_cli(["compare", str(path), *README_RUNS, "--json", "--png", str(png)])
    assert code == 0, err
    found = json.loads(out)  # the whole of stdout: one object, nothing else
    assert found["a"] == "2024-T3_3.18mm/plugging" and found["b"] == "2024-T3_3.18mm/large-pstar"
    assert from_json(found) == oracle(results, "plugging", "large-pstar")
    assert found["scenes"] == 584 and found["changed_scenes"] == sum(found["changes"].values())
    for r in found["outcome_ranges"]:
        assert {"plate", "obliquity_deg", "from_m_s", "to_m_s", "scenes", "outcome_a",
                "outcome_b", "max_abs_delta_exit_speed_m_s",
                "max_abs_delta_exit_obliquity_deg"} <= set(r)  # fmt: skip
    assert png.read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"


def test_summary_counts_only(readme_archive):
    path, results = readme_archive
    code, out, err = run_cli(["compare", str(path), *README_RUNS, "--summary"])
    assert code == 0, err
    lines = out.splitlines()
    counts: dict[str, int] = defaultdict(int)
    for ranges in oracle(results, "plugging", "large-pstar").values():
        for r in ranges:
            counts[r[2]] += r[3]
    assert lines[0].startswith("B 2024-T3_3.18mm/large-pstar against A 2024-T3_3.18mm/plugging")
    assert f"{sum(counts.values())} with another outcome" in lines[0]
    assert sorted(lines[1 : 1 + len(counts)]) == sorted(
        f"  {pair}: {n} scenes" for pair, n in counts.items()
    )
    assert len(lines) == 1 + len(counts) + 2  # then all scenes, and those that agree
    assert not [line for line in lines if " m/s (" in line]  # no ranges
    code, out, err = run_cli(["compare", str(path), *README_RUNS, "--summary", "--json"])
    assert code == 0, err
    summary = json.loads(out)
    assert summary["changes"] == counts and "outcome_ranges" not in summary


def test_bad_input_is_one_line(readme_archive, tmp_path):
    path, _ = readme_archive
    other = tmp_path / "two.h5"
    pi.Study.grid("s", ["2024-T3/3.18"], [0], [300.0], pi.Variant("v")).run(archive=other)
    pi.Study.grid("t", ["2024-T3/3.18"], [0], [300.0], pi.Variant("w")).run(archive=other)
    for argv, words in [
        (["compare", str(other), "v", "w"], ("runs of one study only",)),
        (["compare", str(path), "plugging", "nope", "--json"], ("no run 'nope'",)),
        (
            ["compare", str(path), *README_RUNS, "--png", str(tmp_path / "none" / "c.png")],
            ("--png",),
        ),
    ]:
        code, out, err = run_cli(argv)
        assert_one_line(code, err, *words)
        assert out == ""


def test_the_figure_draws_no_line_across_an_outcome_change_and_no_embedment():
    from plateimpact.figures.compared_runs import plot_comparison

    fig = plot_comparison(hand_made().compare("a", "b"))
    (column,) = [ax for ax in fig.axes if ax.get_title() == "2024-T3/3.18, 30°"]
    drawn = {"-": set(), "--": set()}
    for line in column.get_lines():
        drawn[line.get_linestyle()].add(tuple(line.get_xdata()))
    # From ROW_30 by hand: a is P P R R E Ef P P R P and b is E E R R R Ef R R E E at
    # 100 ... 1000 m/s; each stretch of one regime a line (one scene: a dot), embedments none.
    assert drawn["-"] == {(100, 200), (300, 400), (700, 800), (900,), (1000,)}
    assert drawn["--"] == {(300, 400, 500), (700, 800)}
