"""Archives for review (issue 17): runs that xarray opens as they are, exports, the grid
cube, explicit reruns, and format-1 archives read and upgraded."""

from __future__ import annotations

import csv
import shutil
from pathlib import Path
from types import SimpleNamespace

import h5py
import numpy as np
import pytest
import xarray as xr
from test_archive import assert_same
from test_output_files import assert_one_line, run_cli

import plateimpact as pi

FORMAT1 = Path(__file__).parent / "data" / "format1.h5"
#: How far a rerun on this machine may be from values another machine stored, in each
#: column's scale (Vs, 1 rad, Rs, Rs/Vs). Bit for bit holds only on one machine: another
#: libm, numpy or BLAS rounds force evaluations differently in the last bits, which can
#: change which steps are accepted and so move a result by up to the integrator's error.
#: dopri5 at its default rtol 1e-8 is within 1.7e-7 Vs and 1.2e-7 rad of the reference on
#: the benchmark set (README), so two runs are within twice that: 1e-6 leaves room.
RECOMPUTED = 1e-6
SPEEDS = np.array([250.0, 600.0, 1000.0, 1400.0])
OBLIQUITIES = [0.0, 45.0, 70.0]


@pytest.fixture(scope="module")
def archive(tmp_path_factory) -> Path:
    path = tmp_path_factory.mktemp("review") / "a.h5"
    variants = [pi.Variant("plugging"), pi.Variant("large-pstar", failure="intact")]
    study = pi.Study.grid("grid", ["2024-T3/3.18", "SAE1010/1.47"], OBLIQUITIES, SPEEDS, variants)
    study.run(archive=path, craters=True)
    return path


def test_a_run_opens_in_xarray_alone_with_dims_coordinates_and_units(archive):
    run_file = pi.Archive(archive).data_file("grid/plugging")
    ds = xr.open_dataset(run_file, engine="h5netcdf")  # no renaming, no project code
    n = 2 * len(OBLIQUITIES) * SPEEDS.size
    assert ds.sizes["scene"] == n and set(ds["exit_speed"].dims) == {"scene"}
    for name in ("impact_speed", "impact_obliquity", "radius", "mass", "plate", "a", "b"):
        assert name in ds.coords and ds[name].dims == ("scene",), name
    assert ds["impact_speed"].attrs["units"] == "m/s"
    assert ds["impact_obliquity"].attrs["units"] == "rad"
    assert ds["exit_speed"].attrs["units"] == "m/s" and "long_name" in ds["exit_speed"].attrs
    assert list(ds["outcome"].attrs["flag_values"]) == [1, 2, 3]
    assert ds["outcome"].attrs["flag_meanings"] == "ricochet embedment perforation"
    assert set(np.unique(ds["plate"].values)) == {"2024-T3/3.18", "SAE1010/1.47"}
    stored = pi.Archive(archive).results("grid/plugging")
    np.testing.assert_array_equal(ds["exit_speed"].values, stored.exit_speed)
    study = pi.Study.from_archive(archive)
    np.testing.assert_array_equal(ds["impact_speed"].values, study.scenes.impact_speed)
    # CF contiguous ragged arrays: each scene's crater section from its count.
    count = ds["crater_count"]
    assert count.attrs["sample_dimension"] == "crater_point"
    assert int(count.sum()) == ds.sizes["crater_point"] == stored.craters.counts.sum()
    first = ds["crater_depth"].values[: int(count.values[0])]
    np.testing.assert_array_equal(first, stored.craters.row(0)["depth"])


def test_export_writes_a_netcdf_that_opens_the_same_way_and_a_tidy_csv(archive, tmp_path):
    nc, table = tmp_path / "run.nc", tmp_path / "run.csv"
    code, out, err = run_cli(["export", str(archive), "--run", "plugging", "--to", str(nc)])
    assert code == 0, err
    exported = xr.open_dataset(nc, engine="h5netcdf")
    own = xr.open_dataset(pi.Archive(archive).data_file("plugging"), engine="h5netcdf")
    xr.testing.assert_identical(exported.drop_attrs(), own.drop_attrs())
    assert exported.attrs["run"] == "plugging" and exported.attrs["study"] == "grid"
    code, out, err = run_cli(["export", str(archive), "--run", "plugging", "--to", str(table)])
    assert code == 0, err
    rows = list(csv.DictReader(table.open()))
    stored = pi.Archive(archive).results("plugging")
    assert len(rows) == len(stored)
    assert {"impact_speed_m_s", "impact_obliquity_deg", "radius_mm", "mass_g"} <= set(rows[0])
    assert {"exit_speed_m_s", "exit_obliquity_deg", "max_penetration_mm"} <= set(rows[0])
    k = 7
    assert float(rows[k]["exit_obliquity_deg"]) == pytest.approx(
        np.degrees(stored.exit_obliquity[k]), rel=1e-12
    )
    assert float(rows[k]["max_penetration_mm"]) == pytest.approx(
        stored.max_penetration[k] * 1e3, rel=1e-12
    )
    assert rows[k]["outcome"] == pi.Outcome(int(stored.outcome[k])).label
    for bad, words in [("x.txt", ".nc (netCDF-4) or .csv"), (tmp_path, "--to")]:
        code, _, err = run_cli(["export", str(archive), "--run", "plugging", "--to", str(bad)])
        assert_one_line(code, err, words)
    code, _, err = run_cli(["export", str(archive), "--run", "nope", "--to", str(nc)])
    assert_one_line(code, err, "no run 'nope'")


def test_a_grid_study_is_a_cube_over_variant_plate_obliquity_speed(archive):
    results = pi.StudyResults.from_archive(archive)
    cube = results.to_xarray()
    assert cube["exit_speed"].dims == ("variant", "plate", "impact_obliquity", "impact_speed")
    assert cube.sizes == {"variant": 2, "plate": 2, "impact_obliquity": 3, "impact_speed": 4}
    assert cube["impact_speed"].attrs["units"] == "m/s"
    np.testing.assert_array_equal(cube["impact_speed"].values, SPEEDS)
    study = results.study
    for k in range(study.scenes.size):  # every scene in its cell, by an independent lookup
        cell = cube.sel(
            variant="large-pstar",
            plate=study.plate_labels[k],
            impact_obliquity=study.scenes.impact_obliquity[k],
            impact_speed=study.scenes.impact_speed[k],
        )
        assert float(cell["exit_speed"]) == results["large-pstar"].exit_speed[k]
        assert int(cell["outcome"]) == results["large-pstar"].outcome[k]
    keep = np.arange(5)  # five scenes of the grid: not a full grid
    scattered = pi.Study(
        "s", study.scenes.take(keep), [pi.Variant("v")], [study.plate_labels[k] for k in keep]
    )
    with pytest.raises(pi.ParameterError, match="not a grid"):
        scattered.run().to_xarray()


def test_reproducing_twice_is_refused_unless_resume_overwrite_or_as(tmp_path, monkeypatch):
    """Reruns are explicit (with a two-scene stand-in for the report's families)."""
    study = pi.Study.grid("s", ["2024-T3/3.18"], [0], np.array([300.0, 900.0]), pi.Variant("v"))
    path = tmp_path / "a.h5"
    study.run(archive=path)
    index = path.read_bytes()
    with pytest.raises(pi.ArchiveError, match="already has run s/v: keep it"):
        study.check_archive(path)
    assert path.read_bytes() == index
    study.check_archive(path, resume=True)
    study.check_archive(path, overwrite=True)
    study.check_archive(path, run_names={"v": "v@2"})
    with pytest.raises(pi.ParameterError, match="run_names names no variant"):
        study.check_archive(path, run_names={"w": "x"})


def test_reproduce_twice_on_the_command_line(tmp_path, monkeypatch):
    from plateimpact_studies import reproduce

    small = pi.Study.grid("f", ["2024-T3/3.18"], [0], np.array([300.0]), pi.Variant("v"))
    monkeypatch.setattr(
        reproduce, "FAMILIES", [type("F", (), {"study": staticmethod(lambda: small)})]
    )
    crater = pi.Study.grid("c", ["2024-T3/3.18"], [60], np.array([500.0]), pi.Variant("d"))
    monkeypatch.setattr(reproduce.fig35_37_craters_60deg, "study", lambda: crater)
    monkeypatch.setattr(reproduce, "MAP_SAMPLES", 3)
    monkeypatch.setattr(reproduce, "MAP_OBLIQUITIES", np.radians([0.0, 60.0]))
    # the map of one plate, not five (each plate's map is stored, kept or tagged alike)
    presets = pi.presets
    one_plate = {"2024-T3/3.18": presets.plate("2024-T3/3.18")}
    stand_in = SimpleNamespace(
        PLATES=one_plate, plate=presets.plate, DEFAULT_SPHERE=presets.DEFAULT_SPHERE
    )
    monkeypatch.setattr(reproduce, "presets", stand_in)
    monkeypatch.setattr(reproduce, "experiment", lambda *args: [])  # its own test runs it
    # What is checked is the archive's: the figures are not drawn (test_archive's
    # reproduce test draws every one), only named
    drawn = undrawn_figures(monkeypatch)
    figures = ["f.png", "c.png", "outcome_maps.png", "limit_curves.png"]
    out = tmp_path / "r"
    assert run_cli(["reproduce", "--out", str(out)])[0] == 0
    assert drawn == figures
    index = (out / "report.h5").read_bytes()
    code, _, err = run_cli(["reproduce", "--out", str(out)])
    assert_one_line(code, err, "already has run", "--resume", "--overwrite", "--as TAG")
    assert (out / "report.h5").read_bytes() == index  # refused before anything ran
    assert drawn == figures
    assert run_cli(["reproduce", "--out", str(out), "--resume"])[0] == 0
    assert pi.Archive(out / "report.h5").runs() == ["c/d", "f/v"]
    assert run_cli(["reproduce", "--out", str(out), "--as", "b"])[0] == 0
    assert sorted(pi.Archive(out / "report.h5").runs()) == ["c/d", "c/d@b", "f/v", "f/v@b"]
    maps = ["map_2024-T3_3.18", "map_2024-T3_3.18@b"]  # the maps tagged too
    assert sorted(pi.Archive(out / "report.h5").limits_names()) == maps
    assert run_cli(["reproduce", "--out", str(out), "--overwrite"])[0] == 0
    assert len(pi.Archive(out / "report.h5").runs()) == 4
    assert drawn == 4 * figures  # each run that ran draws them again
    code, _, err = run_cli(["reproduce", "--out", str(out), "--resume", "--overwrite"])
    assert code == 2 and "not allowed with" in err
    for tag in ("", "a/b", "two words"):
        code, _, err = run_cli(["reproduce", "--out", str(out), "--as", tag])
        assert_one_line(code, err, "--as", "printable tag")


def undrawn_figures(monkeypatch) -> list[str]:
    """The names of the figures saved from now on, in order, none of them drawn or written
    (the report's figure families, crater sections and maps)."""
    from plateimpact.figures import exit_curves, limits_and_maps, saving, study_paths

    for module, plot in [(exit_curves, "plot_study"), (study_paths, "plot_study_paths"),
                         (limits_and_maps, "plot_outcome_map"),
                         (limits_and_maps, "plot_limit_curves")]:  # fmt: skip
        monkeypatch.setattr(module, plot, lambda *args, **kwargs: None)
    drawn: list[str] = []

    def named(figure: object, path: str, *args: object, **kwargs: object) -> None:
        drawn.append(Path(path).name)

    monkeypatch.setattr(saving, "save", named)
    return drawn


def assert_recomputed(rerun: pi.BatchResult, stored: pi.BatchResult, scenes: pi.SceneBatch):
    """``rerun`` is ``stored`` computed again, here: the same outcomes and failures, every
    value within RECOMPUTED of its scale, and the same crater depths."""
    np.testing.assert_array_equal(rerun.outcome, stored.outcome)
    np.testing.assert_array_equal(rerun.plate_failed, stored.plate_failed)
    radius, speed = scenes.radius, scenes.impact_speed
    scales = {"exit_speed": speed, "exit_obliquity": 1.0, "contact_time": radius / speed,
              "max_penetration": radius, "failure_time": radius / speed,
              "failure_penetration": radius, "failure_lateral": radius}  # fmt: skip
    assert set(scales) | {"outcome", "plate_failed"} == set(stored.columns)
    for name, scale in scales.items():
        new, old = rerun.columns[name], stored.columns[name]
        np.testing.assert_array_equal(np.isnan(new), np.isnan(old), err_msg=name)
        gap = np.nan_to_num(np.abs(new - old)) / scale
        assert np.all(gap <= RECOMPUTED), (name, gap.max())
    assert rerun.craters is not None and stored.craters is not None
    deepest = [[craters.row(i)["depth"].max() for i in range(scenes.size)]
               for craters in (rerun.craters, stored.craters)]  # fmt: skip
    assert np.all(np.abs(np.subtract(*deepest)) <= RECOMPUTED * radius)


def test_a_format_1_archive_is_read_refused_for_appends_and_upgraded(tmp_path):
    path = tmp_path / "old.h5"
    shutil.copy(FORMAT1, path)
    old = pi.Archive(path)
    assert old.version() == 1
    assert old.runs() == ["v1/plugging", "v1/hinge", "v1/plugging.2"]
    hinge = old.results("hinge")
    assert hinge.craters is not None and hinge.trajectory is not None
    assert "failure_finger_angle" in hinge.trajectory.values
    study = pi.Study.from_archive(path)
    rerun = pi.Study.grid("v1", ["2024-T3/3.18"], [0, 60], np.array([300.0, 1100.0]),
                          pi.Variant("hinge", failure="hinge")).run(craters=True)  # fmt: skip
    # An independent rerun of the stored study, on this machine: within a tolerance of
    # what another machine stored (stored values are compared bit for bit below).
    assert_recomputed(rerun["hinge"], hinge, study.scenes)
    assert study.scenes.size == 4 and old.limits_names() == ["l"]
    before = path.read_bytes()
    with pytest.raises(pi.ArchiveError, match="plateimpact upgrade"):
        study.run(archive=path, run_names={"plugging": "new", "hinge": "new2"})
    assert path.read_bytes() == before
    code, out, err = run_cli(["upgrade", str(path)])
    assert code == 0, err
    kept = tmp_path / "old.h5.format1.h5"
    assert kept.read_bytes() == before  # the old file, renamed, never written
    new = pi.Archive(path)
    assert new.version() == 2 and new.runs() == old.runs() == pi.Archive(kept).runs()
    for run in new.runs():
        assert_same(pi.Archive(kept).results(run), new.results(run))
        assert new.metadata(run) == pi.Archive(kept).metadata(run)
    assert new.record("l").attributes == pi.Archive(kept).record("l").attributes
    with h5py.File(
        new.real.parent
        / f"{path.name}.d"
        / next(p.name for p in new.data.iterdir() if p.name.startswith("limits."))
    ) as f:
        assert f["lines/fixed"].attrs["units"] == "rad"  # units kept for h5py readers
    code, _, err = run_cli(["upgrade", str(path)])
    assert_one_line(code, err, "format version 2: nothing to upgrade")
