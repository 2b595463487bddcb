"""The netCDF files an archive and ``export`` write, checked by the IOOS compliance-checker
against CF 1.11 (an independent reading of the conventions, installed from the test
extra): every check at every priority passes, the global ``title`` and ``history`` (CF
§2.6.2) included, and xarray opens each file with no warning. The files: a run, its
study's scenes and the run exported; a stored record of every kind (limits, an outcome
map, an uncertainty study's sampled limits, Sobol' indices and probability map) and a
record exported; and each layout of file in the archive ``plateimpact reproduce`` writes."""

from __future__ import annotations

import contextlib
import copy
import functools
import json
import warnings
from collections.abc import Callable, Iterator
from pathlib import Path

import numpy as np
import pytest
import xarray
from compliance_checker.cf import util as checker_util
from compliance_checker.runner import CheckSuite, ComplianceChecker
from test_output_files import run_cli

import plateimpact as pi
from plateimpact import limits, presets

# the checker's own notice about a checker of another standard it loads alongside
pytestmark = pytest.mark.filterwarnings("ignore:The ioos_sos checker is deprecated")


@pytest.fixture(scope="module")
def files(tmp_path_factory) -> list[Path]:
    """A run with trajectories and craters, its study's scenes, and the run exported."""
    where = tmp_path_factory.mktemp("cf")
    study = pi.Study.grid("s", ["2024-T3/3.18"], [0.0, 60.0], np.array([300.0, 900.0]),
                          pi.Variant("v"))  # fmt: skip
    study.run(archive=where / "a.h5", record_trajectory=True, craters=True)
    exported = where / "exported.nc"
    code, _, err = run_cli(["export", str(where / "a.h5"), "--run", "s/v", "--to", str(exported)])
    assert code == 0, err
    data = sorted((where / "a.h5.d").glob("*.nc"))
    assert len(data) == 2  # the scenes file and the run's
    return [*data, exported]


@pytest.fixture(scope="module")
def records(tmp_path_factory) -> list[Path]:
    """Every kind of stored record, tiny (two lines, a 2 x 4 map, four samples), limits
    with no boundary (a dimension of size 0), and the map exported."""
    where = tmp_path_factory.mktemp("cf-records")
    archive, simulation = where / "r.h5", pi.Simulation.from_names()
    sphere, plate = presets.DEFAULT_SPHERE, presets.plate("2024-T3/3.18")
    found = limits.along_speed(simulation, sphere, plate, np.radians([0.0, 45.0]),
                               (100.0, 900.0), resolution=50.0)  # fmt: skip
    limits.archive_limits(archive, "bands", found)
    thin = presets.plate("2024-T3/1.27")  # perforated at every speed: no boundary at all
    none = limits.along_speed(simulation, sphere, thin, [0.0], (1500.0, 2000.0), resolution=100.0)
    assert not none.lines[0].boundaries
    limits.archive_limits(archive, "none", none)
    grid = limits.outcome_map(simulation, sphere, plate, (100.0, 1000.0), 4, np.radians([0, 60]))
    limits.archive_limits(archive, "map", grid)
    spec = {"preset": "2024-T3/3.18", "failure": "plugging", "samples": 4, "seed": 6,
            "at": {"obliquity_deg": 30.0},
            "inputs": {"pstar_mm": {"uniform": {"low": 2.5, "high": 3.5}},
                       "a_N_m2": {"normal": {"mean": 1.01e9, "sd": 5e7}}}}  # fmt: skip
    (where / "limits.json").write_text(json.dumps(spec))
    spec["at"]["speed_m_s"] = 420.0
    (where / "at.json").write_text(json.dumps(spec))
    for argv in (["limits.json", "--limits"], ["at.json", "--sobol", "16"],
                 ["at.json", "--speeds", "600,300", "--obliquities", "0,45"]):  # fmt: skip
        code, _, err = run_cli(["uncertainty", str(where / argv[0]), *argv[1:],
                                "--archive", str(archive)])  # fmt: skip
        assert code == 0, err
    exported = where / "map.nc"
    code, _, err = run_cli(["export", str(archive), "--record", "map", "--to", str(exported)])
    assert code == 0, err
    stored = sorted((where / "r.h5.d").glob("limits.*.nc"))
    assert len(stored) == 6  # two limits, a map, and the uncertainty study's three
    return [*stored, exported]


#: The checker's helpers that list a file's variables of one kind (its time, axis,
#: auxiliary coordinate, latitude, ... variables): each a function of the open file alone,
#: which reads it and never writes it (as get_coordinate_variables, which the checker
#: itself caches per file). It calls them again for each variable and check, for most of
#: its time on these files: :func:`helpers_once_per_file` works each out once per file.
PER_FILE_HELPERS = (
    "get_auxiliary_coordinate_variables", "get_axis_variables", "get_time_variables",
    "get_time_variable", "get_latitude_variables", "get_longitude_variables",
    "get_z_variables", "get_cell_boundary_variables", "get_bounds_variables",
    "get_platform_variables", "get_instrument_variables",
)  # fmt: skip


@contextlib.contextmanager
def helpers_once_per_file() -> Iterator[None]:
    """While open, each of :data:`PER_FILE_HELPERS` computed once per file (or group) it
    is given, each caller handed its own copy of the answer; a name the installed checker
    lacks is skipped, a call with more arguments than the file passed through (the
    checks are the same, at worst slower)."""
    answers: dict[tuple[str, int], tuple[object, object]] = {}

    def once(name: str, helper: Callable[..., object]) -> Callable[..., object]:
        @functools.wraps(helper)
        def cached(nc: object, *more: object) -> object:
            if more:
                return helper(nc, *more)
            if (name, id(nc)) not in answers:  # the file kept: its id not reused meanwhile
                answers[name, id(nc)] = (nc, helper(nc))
            return copy.copy(answers[name, id(nc)][1])

        return cached

    helpers = {name: getattr(checker_util, name) for name in PER_FILE_HELPERS
               if callable(getattr(checker_util, name, None))}  # fmt: skip
    try:
        for name, helper in helpers.items():
            setattr(checker_util, name, once(name, helper))
        yield
    finally:
        for name, helper in helpers.items():
            setattr(checker_util, name, helper)


@functools.cache
def load_checkers() -> None:
    CheckSuite.load_all_available_checkers()


def failed_checks(path: Path, report_file: Path) -> list[tuple[str, str, list[str]]]:
    """(priority, check, messages) of every CF 1.11 check the file does not pass fully."""
    load_checkers()
    with helpers_once_per_file():
        ComplianceChecker.run_checker(
            str(path), ["cf:1.11"], 0, "normal", output_filename=str(report_file),
            output_format="json",
        )  # fmt: skip
    report = json.loads(report_file.read_text())["cf:1.11"]
    assert report["possible_points"] > 100  # the checks ran
    failed = []
    for priority in ("high_priorities", "medium_priorities", "low_priorities"):
        for check in report[priority]:
            scored, possible = check["value"]
            if scored < possible:
                failed.append((priority, check["name"], check["msgs"]))
    return failed


def test_every_file_passes_every_cf_check(files, records, tmp_path):
    for path in [*files, *records]:
        assert failed_checks(path, tmp_path / "report.json") == [], path.name


@functools.cache
def opened(path: Path) -> xarray.Dataset:
    """The file as xarray opens it, any warning an error; read once per file (the tests
    only read what it returns)."""
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        with xarray.open_dataset(path, engine="h5netcdf") as data:
            assert data.attrs["Conventions"] == "CF-1.11"
            assert data.attrs["title"].startswith("plateimpact ")
            return data.load()


def test_every_file_says_what_it_is_and_opens_in_xarray_without_a_warning(files, records):
    for path in files:
        data = opened(path)
        assert "s/v" in data.attrs["history"] or "study s" in data.attrs["history"]
        # a run's trajectories are a CF discrete sampling geometry (§9.3.3: contiguous
        # ragged array), one per scene; the scenes file has none
        if "trajectory_count" in data:
            assert data.attrs["featureType"] == "trajectory"
            assert data["scene"].attrs["cf_role"] == "trajectory_id"
            assert data["trajectory_count"].attrs["sample_dimension"] == "trajectory_sample"
        else:
            assert "featureType" not in data.attrs
    assert sum("trajectory_count" in opened(path) for path in files) == 2  # run, export
    for path in records:
        data = opened(path)
        assert data.attrs["history"].startswith(data.attrs["creation_time"])
        assert data.attrs["description"].split(";")[0] in data.attrs["title"]
        for name, variable in data.variables.items():  # units on every number
            assert variable.dtype.kind in "OU" or "units" in variable.attrs, (path.name, name)


def test_a_record_is_labelled_by_its_dimensions(records):
    """Each record's variables over the axes they truly index: a map's grid over its
    obliquities and speeds, which are its lines too; limits' lines with their fixed
    obliquity; the uncertainty study's samples, inputs and points."""
    named = {path.name.split(".")[1]: opened(path) for path in records[:-1]}
    kinds = {data.attrs["kind"]: data for data in named.values()}
    grid = named["map"]
    assert grid["regime"].dims == ("impact_obliquity", "impact_speed")
    assert grid["ballistic_limit"].dims == ("impact_obliquity",)
    assert grid["impact_speed"].attrs["units"] == "m/s" and grid.sizes["impact_speed"] == 4
    assert named["none"].sizes["boundary"] == 0 and named["none"].sizes["line"] == 1
    bands = named["bands"]
    np.testing.assert_array_equal(bands["impact_obliquity"], np.radians([0.0, 45.0]))
    assert bands["ballistic_limit"].dims == ("line",) and "impact_obliquity" in bands.coords
    assert set(bands["boundary_line"].values) == {0, 1}
    sampled = kinds["uncertainty_limits"]
    assert sampled["ballistic_limit"].dims == ("obliquity", "sample")
    assert sampled["sampled_critical_penetration"].attrs["units"] == "m"
    assert list(kinds["uncertainty_indices"]["input_name"].values) == ["pstar_mm", "a_N_m2"]
    probabilities = kinds["uncertainty_map"]
    np.testing.assert_array_equal(probabilities["impact_speed"], [600.0, 300.0])  # as asked
    counts = sum(probabilities[f"{o}_count"] for o in ("ricochet", "embedment", "perforation"))
    assert (counts == 4).all()  # every sample ends somewhere at every point
    exported = opened(records[-1])
    xarray.testing.assert_identical(exported, grid)  # the stored map, attributes and all


def test_every_layout_in_the_reproduce_archive_passes_every_cf_check(quick_report, tmp_path):
    """The data files of the archive ``plateimpact reproduce`` writes: one file of each
    layout (the same variables and global attribute names: a study's runs differ in
    their numbers only) checked, and every file opened in xarray with no warning."""
    data = sorted((quick_report / "report.h5.d").glob("*.nc"))
    layouts: dict[tuple[frozenset[str], frozenset[str]], Path] = {}
    for path in data:
        opened_file = opened(path)
        key = (frozenset(opened_file.variables), frozenset(opened_file.attrs))
        layouts.setdefault(key, path)
    # STUDY.RUN.DIGEST.nc or limits.NAME.DIGEST.nc: a run, a study's scenes, the crater
    # study's run (with crater sections), the outcome maps
    kinds = {path.name.rsplit(".", 3)[1] for path in layouts.values()}
    assert {"plugging", "scenes", "default"} <= kinds, kinds
    assert any(path.name.startswith("limits.map_") for path in layouts.values())
    for path in layouts.values():
        assert failed_checks(path, tmp_path / "report.json") == [], path.name
