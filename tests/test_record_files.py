"""Stored records' files across layouts, and ``plateimpact export --record``: a record
written before records were netCDF (made here, tests/old_records.py) reads back as
written and exports as the same netCDF file its netCDF twin exports as; a bad name,
flag or kind is one line (docs/archive.md, "Limits and outcome maps")."""

from __future__ import annotations

import json
import math

import h5py
import numpy as np
import pytest
import xarray
from old_records import to_old_layout
from test_limits_archive import assert_same_limits, record_file
from test_output_files import assert_one_line, old_file, run_cli

import plateimpact as pi
from plateimpact import limits, presets
from plateimpact.storage.records import Record, RecordColumn, index_column
from plateimpact.uncertainty.record_columns import map_columns

SPHERE, PLATE = presets.DEFAULT_SPHERE, presets.plate("2024-T3/3.18")


@pytest.fixture(scope="module")
def found() -> dict[str, limits.Limits | limits.OutcomeMap]:
    """Tiny limits of both kinds of line, a tiny map, and limits with no boundary."""
    simulation = pi.Simulation.from_names()
    return {
        "speed": limits.along_speed(simulation, SPHERE, PLATE, np.radians([0.0, 45.0]),
                                    (100.0, 900.0), resolution=50.0),
        "obliquity": limits.along_obliquity(simulation, SPHERE, PLATE, [600.0],
                                            resolution=math.radians(5.0)),
        "map": limits.outcome_map(simulation, SPHERE, PLATE, (100.0, 1000.0), 4,
                                  np.radians([0.0, 30.0, 60.0])),
        "none": limits.along_speed(simulation, SPHERE, presets.plate("2024-T3/1.27"), [0.0],
                                   (1500.0, 2000.0), resolution=100.0),  # perforated only
    }  # fmt: skip


def exported(archive, name, to) -> xarray.Dataset:
    code, out, err = run_cli(["export", str(archive), "--record", name, "--to", str(to)])
    assert code == 0 and out == f"wrote limits/{name} to {to}\n", err
    with xarray.open_dataset(to, engine="h5netcdf") as data:
        return data.load()


def test_a_record_from_before_netcdf_reads_back_and_exports_as_its_twin(tmp_path, found):
    path = tmp_path / "a.h5"
    for name, what in found.items():
        limits.archive_limits(path, name, what)
    netcdf = {name: exported(path, name, tmp_path / f"{name}.nc") for name in found}
    for name, what in found.items():
        to_old_layout(record_file(path, name))
        with h5py.File(record_file(path, name)) as f:  # the layout of before, truly
            assert "lines/fixed" in f and "Conventions" not in f.attrs
        back = limits.read_limits(path, name)
        assert type(back) is type(what)
        assert_same_limits(getattr(back, "limits", back), getattr(what, "limits", what))
        if name == "map":
            for grid in ("speeds", "obliquities", "regime", "exit_speed", "exit_obliquity"):
                assert getattr(back, grid).tobytes() == getattr(what, grid).tobytes(), grid
        again = exported(path, name, tmp_path / f"{name}.old.nc")
        xarray.testing.assert_identical(again, netcdf[name])  # attributes and digest too


def test_export_record_refuses_in_one_line_and_leaves_the_target(tmp_path, found):
    path, target = tmp_path / "a.h5", tmp_path / "out.nc"
    limits.archive_limits(path, "bands", found["speed"])
    before = old_file(target)
    for argv, words in [
        (["--record", "nope"], ("--record", "no stored limits 'nope'", "stored: bands")),
        (["--record", "bands", "--to", str(tmp_path / "out.csv")], ("--to", ".nc")),
        ([], ("--run", "--record")),
        (["--record", "bands", "--run", "v"], ("--record", "--run")),
    ]:
        to = [] if "--to" in argv else ["--to", str(target)]
        code, _, err = run_cli(["export", str(path), *argv, *to])
        assert_one_line(code, err, *words)
        assert target.read_bytes() == before
    other = Record({"kind": "other"}, {"x": index_column("x", 2, "x")})
    pi.Archive(path).append_record("other", other)
    code, _, err = run_cli(["export", str(path), "--record", "limits/other", "--to", str(target)])
    assert_one_line(code, err, "limits/other", "kind other", "does not export")
    assert target.read_bytes() == before
    # as export --run does: a good export replaces the file, atomically
    assert exported(path, "bands", target)["ballistic_limit"].dims == ("line",)


def test_a_column_without_its_dimensions_is_refused_before_writing(tmp_path):
    """Every column names its dimensions and every dimension has its coordinate
    variable, so that no netCDF dimension-only dataset ever joins the columns."""
    path = tmp_path / "a.h5"
    for columns in [
        {"y": RecordColumn(np.zeros(2), "m", "y")},  # no dimensions
        {"y": RecordColumn(np.zeros(2), "m", "y", dimensions=("x",))},  # x has no variable
        {"x": index_column("x", 3, "x"), "y": RecordColumn(np.zeros(2), "m", "y", "", ("x",))},
    ]:
        with pytest.raises(ValueError):
            pi.Archive(path).append_record("r", Record({"kind": "other"}, columns))
    assert not path.exists()


def test_a_stored_record_whose_columns_disagree_exports_as_damage_in_one_line(tmp_path):
    path, target = tmp_path / "a.h5", tmp_path / "out.nc"
    counts = {o: np.ones((2, 2), dtype=np.int64) for o in ("ricochet", "embedment", "perforation")}
    columns = map_columns(np.array([300.0, 600.0]), np.radians([0.0, 45.0]), counts)
    plate = json.dumps({"material": "2024-T3", "thickness_mm": 3.18})
    record = Record({"kind": "uncertainty_map", "plate": plate}, columns)
    pi.Archive(path).append_record("m", record)
    assert exported(path, "m", target)["ricochet_count"].shape == (2, 2)
    with h5py.File(record_file(path, "m"), "a") as f:  # data are not sealed, only checksummed
        del f["ricochet_count"]
        f["ricochet_count"] = np.ones(3, dtype=np.int64)
    code, _, err = run_cli(["export", str(path), "--record", "m", "--to", str(target)])
    assert_one_line(code, err, "limits/m", "ricochet_count", "damaged")
