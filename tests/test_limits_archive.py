"""Limits and outcome maps in study archives: stored, read back as written, sealed,
readable without plateimpact, appended atomically, shown and compared (docs/archive.md)."""

from __future__ import annotations

import json
import math
import re
import sys

import attrs
import h5py
import numpy as np
import pytest
from forking import forked
from old_records import to_old_layout
from test_archive import flip_bytes
from test_archive_writers import STAGES, archive_maker, debris
from test_limits import ESTAR, E, P
from test_output_files import assert_one_line, run_cli

import plateimpact as pi
from plateimpact import limits, presets
from plateimpact.cli import main
from plateimpact.limits.archived import attributes_of
from plateimpact.storage import append as appending
from plateimpact.storage.lock import locked

SPHERE = presets.DEFAULT_SPHERE
PLATE = "2024-T3/3.18"
OBLIQUITIES = np.radians([0.0, 45.0])


def along_speed(failure: str) -> limits.Limits:
    simulation = pi.Simulation.from_names(failure=failure)
    return limits.along_speed(
        simulation, SPHERE, presets.plate(PLATE), OBLIQUITIES, (100.0, 900.0), resolution=10.0
    )


@pytest.fixture(scope="module")
def plugging() -> limits.Limits:
    return along_speed("plugging")


@pytest.fixture(scope="module")
def hinge() -> limits.Limits:
    return along_speed("hinge")


@pytest.fixture(scope="module")
def by_obliquity() -> limits.Limits:
    return limits.along_obliquity(
        pi.Simulation.from_names(), SPHERE, presets.plate(PLATE), [600.0],
        resolution=math.radians(1.0),
    )  # fmt: skip


@pytest.fixture(scope="module")
def outcome_map() -> limits.OutcomeMap:
    return limits.outcome_map(
        pi.Simulation.from_names(), SPHERE, presets.plate(PLATE), (100.0, 1000.0), 10,
        np.radians([0.0, 30.0, 60.0]),
    )  # fmt: skip


def tiny_study() -> pi.Study:
    return pi.Study.grid("w", [PLATE], [0, 45], np.array([300.0, 900.0]), pi.Variant("v"))


@pytest.fixture(scope="module")
def make_archive(tmp_path_factory):
    """``make_archive(path)``: the tiny study's archive, written once, copied to ``path``."""
    return archive_maker(tmp_path_factory.mktemp("start"))


def assert_same_limits(back: limits.Limits, found: limits.Limits) -> None:
    assert (back.axis, back.tolerance, back.resolution) == (
        found.axis, found.tolerance, found.resolution,
    )  # fmt: skip
    assert (back.scenes, back.passes, back.seconds) == (found.scenes, found.passes, found.seconds)
    assert back.sphere == found.sphere and back.plate == found.plate
    assert back.model == found.model
    assert back.lines == found.lines  # every boundary: low, high, below, above; first; ends
    for line_back, line in zip(back.lines, found.lines, strict=True):
        assert line_back.bands == line.bands
        for named in ("ballistic_limit", "lowest_perforation", "ricochet_limit",
                      "critical_ricochet_obliquity"):  # fmt: skip
            assert getattr(line_back, named) == getattr(line, named), named


# -- storing and reading back ------------------------------------------------------------


def test_limits_and_maps_read_back_as_written(tmp_path, plugging, by_obliquity, outcome_map):
    path = tmp_path / "a.h5"
    assert limits.archive_limits(path, "plugging", plugging) == "plugging"
    assert limits.archive_limits(pi.Archive(path), "critical", by_obliquity) == "critical"
    assert limits.archive_limits(str(path), "map", outcome_map) == "map"
    assert_same_limits(limits.read_limits(path, "plugging"), plugging)
    assert_same_limits(limits.read_limits(path, "limits/critical"), by_obliquity)
    back = limits.read_limits(path, "map")
    assert isinstance(back, limits.OutcomeMap)
    assert_same_limits(back.limits, outcome_map.limits)
    for name in ("speeds", "obliquities", "regime", "exit_speed", "exit_obliquity"):
        stored, computed = getattr(back, name), getattr(outcome_map, name)
        assert stored.dtype == computed.dtype and stored.shape == computed.shape, name
        assert stored.tobytes() == computed.tobytes(), name  # bit for bit, NaN included
    assert len(back.boundary_curves()) == len(outcome_map.boundary_curves())


def test_a_name_taken_gets_the_next_number_and_studies_are_untouched(
    tmp_path, plugging, make_archive
):
    path = tmp_path / "a.h5"
    make_archive(path)
    names = [limits.archive_limits(path, "plugging", plugging) for _ in range(3)]
    assert names == ["plugging", "plugging.2", "plugging.3"]
    assert limits.stored_limits(path) == names == pi.Archive(path).limits_names()
    archive = pi.Archive(path)
    assert archive.studies() == ["w"] and archive.runs() == ["w/v"]
    assert pi.Study.from_archive(path).name == "w"  # the only study, limits beside it
    tiny_study().run(archive=path, run_names={"v": "v2"})  # runs still append
    assert archive.runs() == ["w/v", "w/v2"] and limits.stored_limits(path) == names


def test_names_that_would_not_survive_or_would_be_misread_are_refused(tmp_path, plugging):
    path = tmp_path / "a.h5"
    for name in ["", "a/b", " padded", "tab\there", "runs", "scenes"]:
        with pytest.raises(pi.ParameterError):
            limits.archive_limits(path, name, plugging)
    assert not path.exists()
    with pytest.raises(pi.ParameterError, match="Limits or an OutcomeMap"):
        limits.archive_limits(path, "x", plugging.lines[0])
    study = pi.Study.grid("limits", [PLATE], [0], np.array([300.0]), pi.Variant("v"))
    with pytest.raises(pi.ArchiveError, match="study name 'limits' is reserved"):
        study.run(archive=path)  # refused before any scene runs
    assert not path.exists()


def test_an_older_archive_with_a_study_named_limits_stays_a_study(tmp_path, plugging, make_archive):
    path = tmp_path / "a.h5"
    make_archive(path)
    with h5py.File(path, "a") as f:
        f.move("w", "limits")  # as an older plateimpact let a study be named
    archive = pi.Archive(path)
    assert archive.studies() == ["limits"] and archive.runs() == ["limits/v"]
    assert archive.limits_names() == []
    before = path.read_bytes()
    with pytest.raises(pi.ArchiveError, match="holds a study named 'limits'"):
        limits.archive_limits(path, "plugging", plugging)
    assert path.read_bytes() == before


def test_unknown_names_list_what_is_stored(tmp_path, plugging):
    path = tmp_path / "a.h5"
    limits.archive_limits(path, "plugging", plugging)
    with pytest.raises(pi.UnknownNameError, match=r"no stored limits 'nope'.*stored: plugging"):
        limits.read_limits(path, "nope")


# -- the seal and damage -------------------------------------------------------------------


@pytest.mark.parametrize(
    ("damage", "message"),
    [
        (lambda g: g.attrs.__setitem__("tolerance", 0.02), "digest does not match"),
        (lambda g: g.attrs.__setitem__("model", "{}"), "digest does not match"),
        (lambda g: g.attrs.__delitem__("attributes_sha256"), "digest is missing"),
        (lambda g: g.parent.attrs.__setitem__("description", "x"), "digest does not match"),
    ],
)
def test_damaged_attributes_are_an_archive_error(tmp_path, plugging, damage, message):
    path = tmp_path / "a.h5"
    limits.archive_limits(path, "plugging", plugging)
    with h5py.File(path, "a") as f:
        damage(f["limits/plugging"])
    with pytest.raises(pi.ArchiveError, match=message):
        limits.read_limits(path, "plugging")
    code, _, err = run_cli(["show", str(path)])
    assert_one_line(code, err, message)


def test_damaged_data_is_an_archive_error(tmp_path, plugging):
    path = tmp_path / "a.h5"
    limits.archive_limits(path, "plugging", plugging)
    flip_bytes(record_file(path, "plugging"), "boundary_low")
    with pytest.raises(pi.ArchiveError, match="damaged"):
        limits.read_limits(path, "plugging")


def record_file(path, name):
    """The data file of the stored record ``name`` (h5py alone: the index's link)."""
    with h5py.File(path, "r") as f:
        return path.parent / f["limits"].get(name, getlink=True).filename


CRASHES_HDF5 = b"long_name\x00\x00\x00\x00\x00\x00\x00\x19\x01"


def test_a_dataset_attribute_that_crashes_hdf5_is_never_read(tmp_path, plugging):
    """Found by fuzzing ``show`` (records in the layout before netCDF): a flipped bit in
    the datatype of a dataset's ``long_name`` (a variable-length kind that does not
    exist) makes libhdf5 crash when the attribute is read. Reading a record reads no
    dataset attributes (they are for readers without plateimpact); the data,
    checksummed, reads back whole. A netCDF record's object headers carry checksums:
    there the same flip is damage, said in one line. Run in forked children, so that a
    crash fails the test instead of ending pytest."""
    path = tmp_path / "a.h5"
    limits.archive_limits(path, "plugging", plugging)
    netcdf = record_file(path, "plugging").read_bytes()
    to_old_layout(record_file(path, "plugging"))
    data = record_file(path, "plugging").read_bytes()
    assert data.count(CRASHES_HDF5) > 10  # every dataset's long_name, as h5py lays it out
    damaged = data.replace(CRASHES_HDF5, CRASHES_HDF5[:-1] + b"\x05")
    record_file(path, "plugging").write_bytes(damaged)
    plain = forked(lambda: h5py.File(path)["limits/plugging/sphere/radius"].attrs["long_name"])
    assert plain.returncode != 0

    def read_and_show() -> None:
        print(limits.read_limits(path, "plugging").lines[1].ballistic_limit)
        sys.exit(main(["show", str(path)]))

    done = forked(read_and_show)
    assert done.returncode == 0, done.stderr
    assert float(done.stdout.splitlines()[0]) == plugging.lines[1].ballistic_limit
    assert "limits/plugging: limits along impact speed" in done.stdout
    assert netcdf.count(CRASHES_HDF5) > 10
    damaged = netcdf.replace(CRASHES_HDF5, CRASHES_HDF5[:-1] + b"\x05")
    record_file(path, "plugging").write_bytes(damaged)
    done = forked(lambda: sys.exit(main(["show", str(path)])))  # as the command ends
    assert_one_line(done.returncode, done.stderr, "limits/plugging", "damaged")


# -- reviewed without plateimpact ------------------------------------------------------------


def test_the_file_reads_in_plain_h5py_with_units_everywhere(
    tmp_path, plugging, outcome_map, make_archive
):
    path = tmp_path / "a.h5"
    make_archive(path)
    limits.archive_limits(path, "plugging", plugging)
    limits.archive_limits(path, "map", outcome_map)
    datasets: list[h5py.Dataset] = []
    with h5py.File(path, "r") as f:  # no project code from here on
        for name in f["limits"]:  # each an external link to the record's own file
            f["limits"][name].visititems(
                lambda _, obj: datasets.append(obj) if isinstance(obj, h5py.Dataset) else None
            )
        assert len(datasets) > 30
        for ds in datasets:
            assert {"units", "long_name", "description"} <= set(ds.attrs), ds.name
            assert ds.fletcher32 and ds.chunks is not None, ds.name
        group = f["limits/plugging"]
        assert group.attrs["kind"] == "limits" and group.attrs["axis"] == "impact_speed"
        assert group.attrs["tolerance"] == 0.01 and group.attrs["tolerance_units"] == "m/s"
        assert group.attrs["resolution"] == 10.0 and group.attrs["resolution_units"] == "m/s"
        assert json.loads(group.attrs["plate"])["thickness_mm"] == 3.18
        assert json.loads(group.attrs["model"])["failure"] == "plugging"
        assert group["impact_obliquity"].attrs["units"] == "rad"  # each line's obliquity
        np.testing.assert_array_equal(group["impact_obliquity"][()], OBLIQUITIES)
        assert group["boundary_low"].attrs["units"] == "m/s"
        assert group["plate_a"].attrs["units"] == "N/m^2" and group["sphere_mass"][0] > 0
        # a reviewer's ballistic limit at 45 deg: the last boundary into perforation (code 7)
        line, above = group["boundary_line"][()], group["regime_above"][()]
        low, high = group["boundary_low"][()], group["boundary_high"][()]
        last = np.flatnonzero((line == 1) & (above == 7))[-1]
        assert 0.5 * (low[last] + high[last]) == plugging.lines[1].ballistic_limit
        assert group["ballistic_limit"][1] == plugging.lines[1].ballistic_limit
        regimes = json.loads(group.attrs["regimes"])
        assert regimes["3"] == "ricochet after failure" and regimes["7"] == "perforation"
        codes = group["regime_above"].attrs
        flags = dict(zip(codes["flag_values"], codes["flag_meanings"].split(), strict=True))
        assert flags == {int(k): v.replace(" ", "_") for k, v in regimes.items()}
        grid = f["limits/map"]
        assert grid["regime"].shape == (3, 10) and grid["exit_speed"].attrs["units"] == "m/s"
        assert grid["exit_obliquity"].attrs["units"] == "rad"
        np.testing.assert_array_equal(grid["impact_speed"][()], outcome_map.speeds)


# -- appended as runs are: atomically, under the lock -----------------------------------------


@pytest.mark.parametrize("stage", STAGES)
def test_a_failed_append_of_limits_leaves_the_archive_as_it_was(
    tmp_path, stage, monkeypatch, plugging, make_archive
):
    path = tmp_path / "a.h5"
    make_archive(path)
    limits.archive_limits(path, "plugging", plugging)
    before = path.read_bytes()

    def fail(where: str) -> None:
        if where == stage:
            raise OSError(28, "No space left on device")

    monkeypatch.setattr(appending, "fault_point", fail)
    with pytest.raises(pi.ArchiveError, match="cannot add limits/plugging: No space left"):
        limits.archive_limits(path, "plugging", plugging)
    assert path.read_bytes() == before and debris(tmp_path) == []
    monkeypatch.undo()
    assert limits.archive_limits(pi.Archive(path, wait=0.0), "plugging", plugging) == "plugging.2"


def test_a_failure_letting_go_of_the_lock_keeps_the_limits_and_says_so(
    tmp_path, monkeypatch, plugging
):
    path = tmp_path / "a.h5"

    def fail(where: str) -> None:
        if where == "unlock":
            raise OSError(5, "Input/output error")

    monkeypatch.setattr(appending, "fault_point", fail)
    with pytest.raises(pi.ArchiveError, match="limits/plugging was added, then letting go"):
        limits.archive_limits(path, "plugging", plugging)
    monkeypatch.undo()
    assert limits.stored_limits(path) == ["plugging"]


@pytest.mark.filterwarnings("ignore::plateimpact.base.errors.ArchiveWaitWarning")
def test_limits_that_cannot_wait_for_another_writer_are_saved_aside(
    tmp_path, plugging, make_archive
):
    path = tmp_path / "a.h5"
    make_archive(path)
    before = path.read_bytes()
    archive = pi.Archive(path, wait=0.0)
    with locked(archive.path, archive.real, archive.lock_path, 1.0):
        with pytest.raises(pi.ArchiveError, match="limits/plugging saved to ") as info:
            limits.archive_limits(archive, "plugging", plugging)
    side = str(info.value).rsplit("saved to ", 1)[1]
    assert path.read_bytes() == before
    assert_same_limits(limits.read_limits(side, "plugging"), plugging)


# -- comparing ------------------------------------------------------------------------------


def test_compare_limits_pairs_boundaries_by_regimes_and_reports_bands_in_one_only(plugging):
    """Lines built by hand: B has a band of embedment after failure that A lacks."""
    base = plugging.lines[0]
    a = attrs.evolve(base, boundaries=(limits.Boundary(399.99, 400.0, E, P),), first=E)
    twice = (limits.Boundary(379.99, 380.0, E, ESTAR), limits.Boundary(409.99, 410.0, ESTAR, P))
    b = attrs.evolve(base, boundaries=twice, first=E)
    comparison = limits.compare_limits(
        attrs.evolve(plugging, lines=(a,)), attrs.evolve(plugging, lines=(b,))
    )
    (line,) = comparison.lines
    assert [(s.below, s.above, s.a is None, s.b is None) for s in line.boundaries] == [
        (E, ESTAR, True, False), (E, P, False, True), (ESTAR, P, True, False),
    ]  # fmt: skip
    assert [band.regime for band in line.bands_only_in_b] == [ESTAR] and not line.bands_only_in_a
    assert line.bands_only_in_b[0].start == pytest.approx(379.995)
    assert comparison.to_json()["lines"][0]["bands_only_in_b"][0]["from_m_s"] == pytest.approx(
        379.995
    )
    # the same pair twice on a line: the k-th with the k-th
    bounce = (limits.Boundary(299.99, 300.0, E, P), limits.Boundary(499.99, 500.0, P, E),
              limits.Boundary(599.99, 600.0, E, P))  # fmt: skip
    moved = tuple(attrs.evolve(x, low=x.low + 1.0, high=x.high + 1.0) for x in bounce)
    comparison = limits.compare_limits(
        attrs.evolve(plugging, lines=(attrs.evolve(base, boundaries=bounce, first=E),)),
        attrs.evolve(plugging, lines=(attrs.evolve(base, boundaries=moved, first=E),)),
    )
    assert [s.shift for s in comparison.lines[0].boundaries] == pytest.approx([1.0] * 3)
    with pytest.raises(pi.ParameterError, match="cannot be compared"):
        limits.compare_limits(plugging, attrs.evolve(plugging, axis=limits.OBLIQUITY))


# -- show and compare ------------------------------------------------------------------------


def numbers_after(text: str, words: str) -> list[float]:
    return [float(x) for x in re.findall(re.escape(words) + r" ([-+]?[\d.]+)", text)]


def test_show_lists_limits_and_maps_and_leaves_the_runs_as_they_were(
    tmp_path, plugging, by_obliquity, outcome_map, make_archive
):
    path = tmp_path / "a.h5"
    make_archive(path)
    code, runs_only, _ = run_cli(["show", str(path)])
    assert code == 0
    limits.archive_limits(path, "plugging", plugging)
    limits.archive_limits(path, "critical", by_obliquity)
    limits.archive_limits(path, "map", outcome_map)
    code, out, err = run_cli(["show", str(path)])
    assert code == 0, err
    assert out.startswith(runs_only)  # the runs' listing unchanged, the limits after it
    shown = out[len(runs_only) :]
    assert "limits/plugging: limits along impact speed, 2 line(s)" in shown
    assert "limits/critical: limits along impact obliquity, 1 line(s)" in shown
    assert "limits/map: outcome map, 3 obliquities x 10 speeds (0-60 deg, 100-1000 m/s)" in shown
    assert "plate 2024-T3 3.18 mm" in shown and "poncelet + plugging" in shown
    assert "tolerance 0.01 m/s, resolution 10 m/s" in shown
    assert "tolerance 0.001 deg, resolution 1 deg" in shown
    # each record's code, as recorded: the core's and each plug-in's source hash
    recorded = attributes_of(path, "plugging")["plugins"]
    for slot in ("core", "resistance", "failure", "integrator"):
        digest = recorded[slot]["source_sha256"][:12]
        assert shown.count(f"  code: {slot} ") == 3 and f", source {digest}" in shown
    lines = (*plugging.lines, *outcome_map.limits.lines)  # the map: one line per row
    for named in ("ballistic limit", "ricochet limit"):
        expected = [x for x in (getattr(line, named.replace(" ", "_")) for line in lines) if x]
        assert len(expected) >= 2, named
        shown_values = numbers_after(shown, named)
        assert shown_values == pytest.approx(expected, abs=plugging.tolerance / 2), named
    assert shown.count("ricochet limit none") == 5 - len(numbers_after(shown, "ricochet limit"))
    critical = numbers_after(shown, "critical ricochet obliquity")
    assert critical == pytest.approx(
        [math.degrees(by_obliquity.lines[0].critical_ricochet_obliquity)], abs=5e-4
    )


def expected_shifts(a: limits.LimitLine, b: limits.LimitLine) -> list[tuple[str, str, float]]:
    """The k-th boundary of each (below, above) pair in A with the k-th in B."""
    pairs = []
    for pair in {(x.below, x.above) for x in a.boundaries}:
        mine = [x for x in a.boundaries if (x.below, x.above) == pair]
        theirs = [y for y in b.boundaries if (y.below, y.above) == pair]
        pairs += [
            (x.below.label, x.above.label, y.at - x.at) for x, y in zip(mine, theirs, strict=True)
        ]
    return sorted(pairs)


def test_compare_says_how_far_each_boundary_moved(tmp_path, plugging, hinge):
    path = tmp_path / "a.h5"
    limits.archive_limits(path, "plugging", plugging)
    limits.archive_limits(path, "hinge", hinge)
    code, out, err = run_cli(["compare", str(path), "plugging", "limits/hinge", "--json"])
    assert code == 0, err
    found = json.loads(out)
    assert [line["obliquity_deg"] for line in found["lines"]] == pytest.approx([0.0, 45.0])
    for line, a, b in zip(found["lines"], plugging.lines, hinge.lines, strict=True):
        shifts = sorted((s["below"], s["above"], s["shift_m_s"]) for s in line["boundaries"])
        assert shifts == expected_shifts(a, b)
        assert len(shifts) == len(a.boundaries) == len(b.boundaries)
    moved = [s["shift_m_s"] for line in found["lines"] for s in line["boundaries"]]
    assert max(moved) > 10.0  # a hinge holds longer than a plug: the ballistic limit rises
    code, text, err = run_cli(["compare", str(path), "plugging", "hinge"])
    assert code == 0, err
    rows = [row for row in text.splitlines() if "; shift " in row]
    assert len(rows) == sum(len(line.boundaries) for line in plugging.lines)
    line_45 = [row for row in rows if row.startswith("  obliquity 45 deg: embedment after")]
    shift = hinge.lines[1].ballistic_limit - plugging.lines[1].ballistic_limit
    assert numbers_after(line_45[0], "shift") == pytest.approx([shift], abs=1e-3)


def test_compare_reports_lines_in_one_only(tmp_path, plugging, outcome_map):
    path = tmp_path / "a.h5"
    limits.archive_limits(path, "plugging", plugging)
    limits.archive_limits(path, "map", outcome_map)
    code, out, err = run_cli(["compare", str(path), "plugging", "map", "--json"])
    assert code == 0, err
    found = json.loads(out)
    assert [line["obliquity_deg"] for line in found["lines"]] == [0.0]
    assert found["lines_only_in_a_deg"] == pytest.approx([45.0])
    assert found["lines_only_in_b_deg"] == pytest.approx([30.0, 60.0])
    code, text, err = run_cli(["compare", str(path), "plugging", "map"])
    assert code == 0, err
    assert "obliquity 45 deg: the line is only in plugging" in text
    assert "obliquity 30 deg: the line is only in map" in text


def test_bad_show_and_compare_use_is_one_line(tmp_path, plugging, by_obliquity, make_archive):
    path = tmp_path / "a.h5"
    make_archive(path)
    limits.archive_limits(path, "plugging", plugging)
    limits.archive_limits(path, "critical", by_obliquity)
    png = str(tmp_path / "c.png")
    for argv, words in [
        (["compare", str(path), "plugging", "v"], ("'v' is a run", "'plugging' is stored limits")),
        (["compare", str(path), "v", "limits/plugging"], ("is a run",)),
        (["compare", str(path), "plugging", "nope"], ("no run 'nope'", "limits/plugging", "w/v")),
        (["compare", str(path), "plugging", "critical"], ("along the same axis",)),
        (["compare", str(path), "plugging", "plugging", "--png", png], ("--png draws runs",)),
        (["compare", str(path), "plugging", "plugging", "--summary"], ("--summary counts",)),
    ]:
        code, out, err = run_cli(argv)
        assert_one_line(code, err, *words)
        assert out == ""


def test_compare_json_of_two_runs_is_their_summary(tmp_path):
    path = tmp_path / "a.h5"
    study = pi.Study.grid("w", [PLATE], [0, 45], np.array([300.0, 900.0]),
                          [pi.Variant("v"), pi.Variant("intact", failure="intact")])  # fmt: skip
    results = study.run(archive=path)
    code, out, err = run_cli(["compare", str(path), "v", "intact", "--json", "--summary"])
    assert code == 0, err
    expected = {"a": "w/v", "b": "w/intact", **results.compare("v", "intact").summary()}
    assert json.loads(out) == expected and expected["changed_scenes"] > 0
