"""Objects for notebooks (issue 25, item 2): short text and escaped HTML in user units,
labelled tables (``to_xarray``, ``to_dataframe``) that say what the archive's run files
and exports say, and fits that take the Shots a shot file reads."""

from __future__ import annotations

import csv
import math

import attrs
import numpy as np
import pytest
import xarray as xr
from test_output_files import run_cli

import plateimpact as pi
from plateimpact import presets
from plateimpact.units import deg

SPHERE = presets.DEFAULT_SPHERE
HOSTILE = '<script>alert("x")</script>'
SPEEDS, OBLIQUITIES_DEG = [300.0, 900.0], [0.0, 45.0]


@pytest.fixture(scope="module")
def archived(tmp_path_factory):
    """A study of a preset plate and one whose material is markup, two variants, archived."""
    preset = presets.plate("2024-T3/3.18")
    hostile = pi.Plate(HOSTILE, preset.thickness, dict(preset.constants))
    variants = [pi.Variant("plugging"), pi.Variant("intact", failure="intact")]
    study = pi.Study.grid("s", [preset, hostile], OBLIQUITIES_DEG, SPEEDS, variants)
    path = tmp_path_factory.mktemp("notebook") / "a.h5"
    return path, study.run(archive=path)


def test_html_escapes_a_hostile_plate_label_and_the_text_stays_one_line(archived):
    _, results = archived
    for shown in (results._repr_html_(), results["plugging"]._repr_html_()):
        assert "<script>" not in shown
        assert "&lt;script&gt;alert(&quot;x&quot;)&lt;/script&gt;/3.18" in shown
    assert "\n" not in repr(results)


def test_html_escapes_a_plug_in_setting(sphere):
    simulation = pi.Simulation.from_names()
    found = pi.limits.along_speed(simulation, sphere, presets.plate("2024-T3/3.18"), [0.0],
                                  (300.0, 700.0))  # fmt: skip
    model = {**found.model, "integrator_settings": {"note": "<img src=x onerror=alert(1)>"}}
    html = attrs.evolve(found, model=model)._repr_html_()
    assert "<img" not in html and "&lt;img src=x onerror=alert(1)&gt;" in html


def test_a_runs_dataset_is_its_archived_file_as_xarray_opens_it(archived):
    path, results = archived
    for run in results.runs:
        own = results[run].to_xarray().drop_attrs()
        stored = xr.open_dataset(pi.Archive(path).data_file(f"s/{run}"), engine="h5netcdf")
        xr.testing.assert_identical(own, stored.drop_attrs())


def test_a_runs_dataframe_is_the_tidy_table_export_writes(archived, tmp_path):
    path, results = archived
    table = tmp_path / "run.csv"
    code, _, err = run_cli(["export", str(path), "--run", "s/plugging", "--to", str(table)])
    assert code == 0, err
    rows = list(csv.DictReader(table.open()))
    frame = results["plugging"].to_dataframe()
    assert set(frame.columns) == set(rows[0])
    for column in frame.columns:
        exported = [row[column] for row in rows]
        if frame[column].dtype.kind == "f":
            np.testing.assert_allclose(frame[column], [float(x) for x in exported], rtol=1e-15)
        elif frame[column].dtype.kind == "b":
            assert [("true" if x else "false") for x in frame[column]] == exported
        else:
            assert [str(x) for x in frame[column]] == exported, column


def test_a_studys_dataframe_has_every_run_and_the_cube_agrees(archived):
    _, results = archived
    frame = results.to_dataframe()
    assert frame.index.names == ["variant", "scene"] and len(frame) == 2 * 8
    cube = results.to_xarray()
    for run, result in results.runs.items():
        rows = frame.loc[run]
        np.testing.assert_array_equal(rows["exit_speed_m_s"], result.exit_speed)
        np.testing.assert_allclose(rows["impact_obliquity_deg"],
                                   np.degrees(results.study.scenes.impact_obliquity))  # fmt: skip
        for k in range(len(result)):  # each row in its cell of the cube
            cell = cube.sel(variant=run, plate=results.study.plate_labels[k],
                            impact_obliquity=results.study.scenes.impact_obliquity[k],
                            impact_speed=results.study.scenes.impact_speed[k])  # fmt: skip
            assert float(cell["exit_speed"]) == rows["exit_speed_m_s"].iloc[k]
    assert frame.attrs["units"]["pstar_mm"] == "mm"  # P*'s key, as the plug-in declares it


def test_a_batch_takes_its_plate_constants_units_from_their_declarations():
    plate = presets.plate("2024-T3/3.18")
    batch = pi.SceneBatch.grid(SPHERE, plate, SPEEDS, np.radians(OBLIQUITIES_DEG))
    declared = pi.Simulation.from_names().model.plate_constants()
    dataset = batch.to_xarray(declared)
    assert dataset["a"].attrs["units"] == "N/m^2"
    assert dataset["critical_penetration"].attrs["units"] == "m"
    frame = batch.to_dataframe(declared)
    np.testing.assert_allclose(frame["pstar_mm"], plate.critical_penetration / 1e-3)
    bare = batch.to_xarray()
    assert "units" not in bare["a"].attrs and "unit unknown" in bare["a"].attrs["description"]
    assert "<th>a [SI]</th>" in batch._repr_html_()


def test_a_subset_of_results_keeps_its_scenes():
    plate = presets.plate("2024-T3/3.18")
    batch = pi.SceneBatch.grid(SPHERE, plate, [250.0, 500.0, 1000.0], [0.0])
    results = pi.Simulation.from_names().run_batch(batch)
    part = results.take(np.array([2, 0]))
    np.testing.assert_array_equal(part.to_dataframe()["impact_speed_m_s"], [1000.0, 250.0])
    both = pi.BatchResult.concat([part, results.take(np.array([1]))])
    np.testing.assert_array_equal(both.scenes.impact_speed, [1000.0, 250.0, 500.0])
    assert "impact speed 250, 500, 1000 m/s" in repr(both)


def test_limits_tables_say_none_as_nan_with_units(sphere):
    simulation = pi.Simulation.from_names()
    found = pi.limits.along_speed(simulation, sphere, presets.plate("2024-T3/1.27"),
                                  [0.0, 45 * deg], (50.0, 600.0))  # fmt: skip
    dataset = found.to_xarray()
    assert dataset["ballistic_limit"].attrs["units"] == "m/s"
    # at normal incidence the sphere never ricochets: no ricochet limit on that line
    assert found.lines[0].ricochet_limit is None and math.isnan(dataset["ricochet_limit"][0])
    np.testing.assert_allclose(dataset["impact_obliquity"], [0.0, 45 * deg])
    assert list(found.to_dataframe().index) == pytest.approx([0.0, 45.0])


def test_a_maps_cells_are_its_regimes(sphere):
    simulation = pi.Simulation.from_names()
    found = pi.limits.outcome_map(simulation, sphere, presets.plate("2024-T3/1.27"),
                                  (100.0, 600.0), 6, np.radians([0.0, 60.0]))  # fmt: skip
    frame = found.to_dataframe()
    assert len(frame) == 12 and frame.index.names == ["impact_obliquity_deg", "impact_speed_m_s"]
    regimes = [pi.limits.Regime.of_code(int(c)) for c in found.regime.ravel()]
    assert list(frame["outcome"]) == [r.outcome.label for r in regimes]
    assert list(frame["plate_failed"]) == [r.plate_failed for r in regimes]
    assert "cells: " in repr(found) and "<th>regime</th>" in found._repr_html_()


def test_a_comparison_says_how_far_the_ballistic_limit_moved(sphere):
    plate = presets.plate("2024-T3/1.27")
    a, b = (pi.limits.along_speed(pi.Simulation.from_names(failure=f), sphere, plate, [0.0],
                                  (50.0, 600.0)) for f in ("plugging", "hinge"))  # fmt: skip
    moved = b.lines[0].ballistic_limit - a.lines[0].ballistic_limit
    comparison = pi.limits.compare_limits(a, b)
    assert f"<td>{moved:.6g}</td>" in comparison._repr_html_()


def go_no_go_shots() -> pi.Shots:
    speeds = [300.0, 310.0, 320.0, 330.0, 340.0, 350.0, 360.0, 370.0]
    return pi.Shots.from_columns({
        "impact_speed_m_s": speeds,
        "impact_obliquity_deg": [30.0] * len(speeds),
        "perforated": [0, 0, 1, 0, 1, 0, 1, 1],
        "weight": [1, 2, 1, 1, 1, 1, 2, 1],
    })  # fmt: skip


def test_the_v50_fits_take_shots_as_they_take_arrays():
    shots = go_no_go_shots()
    arrays = (shots.impact_speed, shots.perforated, shots.weight)
    assert pi.fit_v50(shots, bootstrap=50).to_json() == pi.fit_v50(*arrays, bootstrap=50).to_json()
    assert pi.mil_std_662f(shots, count=2).to_json() == pi.mil_std_662f(*arrays, count=2).to_json()
    with pytest.raises(pi.ParameterError, match="Shots alone"):
        pi.fit_v50(shots, shots.perforated)
    mixed = pi.Shots.from_csv_text("impact_speed_m_s,impact_obliquity_deg,perforated\n"
                                   "300,0,0\n400,30,1\n", source="two.csv")  # fmt: skip
    with pytest.raises(pi.ShotDataError, match=r"two.csv: shots at 2 obliquities \(0, 30 deg\)"):
        pi.fit_v50(mixed)


def test_the_dri_fit_takes_shots_and_leaves_out_what_did_not_perforate():
    shots = pi.Shots.from_columns({
        "impact_speed_m_s": [300.0, 400.0, 500.0, 600.0, 700.0, 250.0],
        "impact_obliquity_deg": [0.0] * 6,
        "outcome": ["perforation"] * 5 + ["ricochet"],
        "residual_speed_m_s": [90.0, 250.0, 370.0, 480.0, 590.0, 40.0],  # the last a rebound
    })  # fmt: skip
    from_shots = pi.fit_dri(shots)
    from_arrays = pi.fit_dri(shots.impact_speed[:5], shots.residual_speed[:5])
    assert (from_shots.R, from_shots.V0) == (from_arrays.R, from_arrays.V0)
    assert f"<tr><td>V0 [m/s]</td><td>{from_shots.V0:.5g}</td>" in from_shots._repr_html_()


def test_the_calibrations_results_show_their_constants_in_user_units():
    from plateimpact_plugins.report import PstarFit, calibrate
    from plateimpact_plugins.report.fits import PstarEstimate
    from plateimpact_plugins.report.pstar_search import Cost

    plate = presets.plate("SAE1010/1.47")
    estimate = PstarEstimate(pstar=4.6e-3, pstar_stderr=0.1e-3, alpha=45 * deg)
    fit = PstarFit(plate, estimate, False, pi.ProbabilityModel(), 20, 5, "", Cost())
    assert "P* 4.6 +/- 0.1 mm; alpha* 45 deg (held)" in repr(fit)
    assert "<tr><td>P* [mm]</td><td>4.6</td><td>0.1</td></tr>" in fit._repr_html_()
    shots = pi.Shots.from_csv_text(
        "impact_speed_m_s,impact_obliquity_deg,residual_speed_m_s\n"
        + "".join(f"{v},0,{r}\n" for v, r in [(500, 180), (700, 450), (900, 680), (1100, 900)])
    )
    report = calibrate(shots, presets.plate("2024-T3/3.18"))
    html = report.newton._repr_html_()
    assert f"<tr><td>a [N/m^2]</td><td>{report.newton.a:.5g}</td>" in html
    assert f"b {report.direct.b:.5g} kg/m^3" in repr(report)
