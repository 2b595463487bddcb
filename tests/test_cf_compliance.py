"""The netCDF files an archive and ``export`` write, checked by the IOOS compliance-checker
against CF 1.11 (an independent reading of the conventions, installed from the test
extra): every check at every priority passes, the global ``title`` and ``history`` (CF
§2.6.2) included, and xarray opens each file with no warning."""

from __future__ import annotations

import json
import warnings
from pathlib import Path

import numpy as np
import pytest
import xarray
from compliance_checker.runner import CheckSuite, ComplianceChecker
from test_output_files import run_cli

import plateimpact as pi

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


def failed_checks(path: Path, report_file: Path) -> list[tuple[str, str, list[str]]]:
    """(priority, check, messages) of every CF 1.11 check the file does not pass fully."""
    CheckSuite.load_all_available_checkers()
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


def test_every_file_passes_every_cf_check(files, tmp_path):
    for path in files:
        assert failed_checks(path, tmp_path / "report.json") == [], path.name


def test_every_file_says_what_it_is_and_opens_in_xarray_without_a_warning(files):
    for path in files:
        with warnings.catch_warnings():
            warnings.simplefilter("error")
            with xarray.open_dataset(path, engine="h5netcdf") as data:
                assert data.attrs["Conventions"] == "CF-1.11"
                assert data.attrs["title"].startswith("plateimpact ")
                assert "s/v" in data.attrs["history"] or "study s" in data.attrs["history"]
