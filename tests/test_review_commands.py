"""Every reviewing command on the archive that ``plateimpact reproduce`` writes: ``show``,
``compare`` (runs and stored limits), ``plot`` (each kind), ``export`` (netCDF and CSV,
every run), ``limits``/``map`` storing into it, and ``upgrade``'s refusal of a format-2
archive. The archive is made once per session by ``reproduce --quick`` (the same code
on small grids; studies/reproduce.py)."""

from __future__ import annotations

import csv
import json
import shutil
from pathlib import Path

import numpy as np
import pytest
from test_output_files import assert_one_line, run_cli

import plateimpact as pi
from plateimpact.registry.plugin_registry import KINDS
from plateimpact_plugins.variable_pstar import SAE1010_TABLE


def _settings_of_every_plugin():
    registry = pi.default_registry()
    for kind in KINDS:
        for name in registry.names(kind):
            cls = registry.get(kind, name)
            for setting, declared in cls.setting_declarations().items():
                if declared.has_default:
                    yield pytest.param(cls, setting, declared, id=f"{kind}.{name}.{setting}")


@pytest.mark.parametrize(("cls", "setting", "declared"), list(_settings_of_every_plugin()))
def test_a_setting_read_back_from_an_archive_describes_itself_as_the_original(
    cls, setting, declared
):
    # What an archive holds is the setting's JSON value; read back, it is plain JSON
    # (a P* table's rows, not a PstarTable) and must describe itself unchanged.
    original = getattr(cls(), setting)
    stored = json.loads(json.dumps(declared.json_value(original)))
    assert declared.format(stored) == declared.format(original)
    assert declared.json_value(stored) == declared.json_value(original)


# -- every reviewing command on the archive reproduce writes ------------------------------


def snapshot(directory: Path) -> dict[str, bytes]:
    """Every file under ``directory`` by relative path, with its bytes."""
    return {
        str(p.relative_to(directory)): p.read_bytes() for p in directory.rglob("*") if p.is_file()
    }


@pytest.fixture(scope="module")
def report(quick_report: Path) -> Path:
    return quick_report / "report.h5"


def test_reproduce_quick_stores_every_study_variant_setting_kind_and_map(report):
    archive = pi.Archive(report)
    # the five families, the crater study and both comparison families' second variants
    assert len(archive.studies()) == 6 and len(archive.runs()) == 8
    failures = {archive.metadata(run)["model"]["failure"] for run in archive.runs()}
    assert failures == {"plugging", "intact", "variable-pstar"}
    assert archive.results("craters_60deg/default").craters is not None
    assert archive.limits_names() == [f"map_{p.replace('/', '_')}" for p in pi.presets.PLATES]


def test_show_lists_every_run_and_stored_map_of_reproduces_archive(report):
    before = snapshot(report.parent)
    code, out, err = run_cli(["show", str(report)])
    assert code == 0 and err == "", err
    archive = pi.Archive(report)
    lines = out.splitlines()
    for run in archive.runs():
        assert run in lines  # the run's own heading line
        result = archive.results(run)
        counts = np.bincount(result.outcome, minlength=4)[1:]
        heading = lines.index(run)
        summary = next(line for line in lines[heading:] if line.endswith(" s") and "wall" in line)
        assert summary.startswith(
            f"  {len(result)} scenes: {counts[0]} ricochet, {counts[1]} embedment, "
            f"{counts[2]} perforation;"
        )
    for name in archive.limits_names():
        assert any(line.startswith(f"limits/{name}: outcome map") for line in lines)
    # the variable-P* run's table, as the plug-in's own default describes it
    table = str(SAE1010_TABLE.as_setting())
    assert any(f"failure: variable-pstar 1 (table {table})" in line for line in lines)
    assert snapshot(report.parent) == before  # a reviewing command writes nothing


def _regime_changes(archive: pi.Archive, a: str, b: str) -> int:
    """Scenes whose outcome or plate failure differs (ricochet -> ricochet after failure
    is a change)."""
    one, other = archive.results(a), archive.results(b)
    changed = (one.outcome != other.outcome) | (one.plate_failed != other.plate_failed)
    return int(np.sum(changed))


@pytest.mark.parametrize(
    ("run_a", "run_b"),
    [
        ("SAE1010_1.47mm/constant-pstar", "SAE1010_1.47mm/variable-pstar"),
        ("2024-T3_3.18mm/plugging", "2024-T3_3.18mm/large-pstar"),
    ],
)
def test_compare_runs_of_reproduces_archive(report, tmp_path, run_a, run_b):
    archive = pi.Archive(report)
    code, out, err = run_cli(["compare", str(report), run_a, run_b])
    assert code == 0 and err == "" and out.startswith(f"B {run_b} against A {run_a}:")
    code, out, err = run_cli(["compare", str(report), run_a, run_b, "--summary", "--json"])
    assert code == 0 and err == "", err
    summary = json.loads(out)
    assert summary["scenes"] == len(archive.results(run_a))
    assert summary["changed_scenes"] == _regime_changes(archive, run_a, run_b) > 0
    png = tmp_path / "compare.png"
    code, out, err = run_cli(["compare", str(report), run_a, run_b, "--png", str(png)])
    assert code == 0 and err == "" and png.read_bytes()[:4] == b"\x89PNG"


def test_compare_stored_maps_of_reproduces_archive(report):
    a, b = "limits/map_2024-T3_3.18", "limits/map_2024-T3_6.35"
    code, out, err = run_cli(["compare", str(report), a, b])
    assert code == 0 and err == "" and out.startswith(f"{b} against {a}: 4 line(s)")
    code, out, err = run_cli(["compare", str(report), a, b, "--json"])
    assert code == 0 and err == "", err
    found = json.loads(out)
    assert (found["a"], found["b"], found["axis"]) == (a, b, "impact_speed")
    # the quick maps' obliquities, 0 to 84 deg by 28
    assert [line["obliquity_deg"] for line in found["lines"]] == pytest.approx([0, 28, 56, 84])
    code, _, err = run_cli(["compare", str(report), a, "2024-T3_3.18mm/plugging"])
    assert_one_line(code, err, "is a run", "stored limits")


@pytest.mark.parametrize(
    ("run", "kind"),
    [
        ("SAE1010_1.47mm/variable-pstar", "exit"),
        ("craters_60deg/default", "trajectory"),
        ("craters_60deg/default", "crater"),
    ],
)
def test_plot_every_kind_from_reproduces_archive(report, tmp_path, run, kind):
    png = tmp_path / f"{kind}.png"
    argv = ["plot", str(report), "--run", run, "--kind", kind, "--out", str(png), "--dpi", "50"]
    code, out, err = run_cli(argv)
    assert code == 0 and err == "" and out == f"figure: {png}\n"
    assert png.read_bytes()[:4] == b"\x89PNG"


def test_plot_overlays_both_runs_of_a_comparison_family(report, tmp_path):
    png = tmp_path / "both.png"
    argv = ["plot", str(report), "--run", "SAE1010_1.47mm/constant-pstar", "--run",
            "SAE1010_1.47mm/variable-pstar", "--out", str(png), "--dpi", "50"]  # fmt: skip
    assert run_cli(argv)[0] == 0 and png.read_bytes()[:4] == b"\x89PNG"


def test_export_every_run_of_reproduces_archive_as_netcdf_and_csv(report, tmp_path):
    import xarray

    archive = pi.Archive(report)
    for run in archive.runs():
        result = archive.results(run)
        stem = tmp_path / run.replace("/", "_")
        code, out, err = run_cli(["export", str(report), "--run", run, "--to", f"{stem}.nc"])
        assert code == 0 and err == "" and out == f"wrote {run} to {stem}.nc\n"
        with xarray.open_dataset(f"{stem}.nc", engine="h5netcdf") as data:
            assert np.array_equal(data["outcome"].values, result.outcome)
            assert np.array_equal(data["exit_speed"].values, result.exit_speed, equal_nan=True)
        code, out, err = run_cli(["export", str(report), "--run", run, "--to", f"{stem}.csv"])
        assert code == 0 and err == "", err
        with open(f"{stem}.csv", newline="") as handle:
            rows = list(csv.DictReader(handle))
        assert len(rows) == len(result)
        exported = np.array([float(row["exit_speed_m_s"]) for row in rows])
        assert np.array_equal(exported, result.exit_speed, equal_nan=True)


def test_export_every_stored_map_of_reproduces_archive_as_netcdf(report, tmp_path):
    import xarray

    names = pi.limits.stored_limits(report)
    assert len(names) == 5  # one map per plate
    for name in names:
        stored = pi.limits.read_limits(report, name)
        target = tmp_path / f"{name}.nc"
        code, out, err = run_cli(["export", str(report), "--record", name, "--to", str(target)])
        assert code == 0 and err == "" and out == f"wrote limits/{name} to {target}\n"
        with xarray.open_dataset(target, engine="h5netcdf") as data:
            assert data["regime"].dims == ("impact_obliquity", "impact_speed")
            assert np.array_equal(data["regime"].values, stored.regime)
            assert np.array_equal(data["impact_speed"].values, stored.speeds)


def test_limits_and_map_stored_into_reproduces_archive_are_shown_and_compared(
    quick_report, tmp_path
):
    copy = tmp_path / "report"
    shutil.copytree(quick_report, copy)
    archive = copy / "report.h5"
    limits = ["limits", "--preset", "SAE1010/1.47", "--obliquities", "0,28", "--speeds",
              "50:2000", "--tolerance", "1", "--archive", str(archive), "--name",
              "mine"]  # fmt: skip
    code, out, err = run_cli(limits)
    assert code == 0 and err == "" and f"archive: {archive} (limits/mine)" in out
    small_map = ["map", "--preset", "SAE1010/1.47", "--speeds", "50:2000:4", "--obliquities",
                 "0,28", "--tolerance", "1", "--png", str(tmp_path / "m.png"), "--dpi", "50",
                 "--archive", str(archive), "--name", "small"]  # fmt: skip
    code, out, err = run_cli(small_map)
    assert code == 0 and err == "" and "(limits/small)" in out
    code, out, err = run_cli(["show", str(archive)])
    assert code == 0 and err == ""
    assert "limits/mine: limits along impact speed, 2 line(s)" in out
    assert "limits/small: outcome map, 2 obliquities x 4 speeds" in out
    # the same plate and model, boundaries to 1 m/s and to 0.01 m/s: within 1 m/s
    code, out, err = run_cli(
        ["compare", str(archive), "limits/map_SAE1010_1.47", "limits/mine", "--json"]
    )
    assert code == 0 and err == "", err
    found = json.loads(out)
    shifts = [
        s["shift_m_s"]
        for line in found["lines"]
        for s in line["boundaries"]
        if s["shift_m_s"] is not None
    ]
    assert shifts and max(abs(s) for s in shifts) <= 1.0
    assert [line["obliquity_deg"] for line in found["lines"]] == pytest.approx([0, 28])


def test_upgrade_refuses_reproduces_format_2_archive_and_leaves_it(report):
    before = snapshot(report.parent)
    code, out, err = run_cli(["upgrade", str(report)])
    assert_one_line(code, err, "format version 2", "nothing to upgrade")
    assert out == "" and snapshot(report.parent) == before
