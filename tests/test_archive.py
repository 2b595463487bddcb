"""Studies and their HDF5 archives: round trip, safety, bad input, comparison, Dask."""

from __future__ import annotations

import os
import pathlib
import shutil
import signal
import subprocess
import sys

import h5py
import numpy as np
import pytest
from forking import forked

import plateimpact as pi
import plateimpact.run.simulation
from plateimpact.cli import main as cli
from plateimpact.limits import stored_limits
from plateimpact.model.crater import crater_section

SPEEDS = np.linspace(150.0, 1200.0, 8)


def small_study(name="t318", trajectory_variant=False):
    variants = [pi.Variant("plugging"), pi.Variant("large-pstar", failure="intact")]
    return pi.Study.grid(name, ["2024-T3/3.18", "SAE1010/1.47"], [0, 45, 60], SPEEDS, variants)


@pytest.fixture(scope="module")
def small_archive(tmp_path_factory) -> pathlib.Path:
    """:func:`small_study` run into an archive once, for the tests that only read it (a
    test that changes it changes a copy)."""
    path = tmp_path_factory.mktemp("small") / "a.h5"
    small_study().run(archive=path)
    return path


def assert_same(a: pi.BatchResult, b: pi.BatchResult) -> None:
    for name, column in a.columns.items():
        np.testing.assert_array_equal(b.columns[name], column, err_msg=name)
        assert b.columns[name].dtype == column.dtype, name
    for ragged in ("trajectory", "craters"):
        x, y = getattr(a, ragged), getattr(b, ragged)
        assert (x is None) == (y is None), ragged
        if x is not None:
            assert list(x.values) == list(y.values) and list(x.per_row) == list(y.per_row)
            np.testing.assert_array_equal(y.counts, x.counts)
            for name, column in [*x.values.items(), *x.per_row.items()]:
                np.testing.assert_array_equal(y[name], column, err_msg=name)


def test_round_trip_is_bit_for_bit(tmp_path):
    study = pi.Study.grid(
        "hinge", ["SAE1010/1.47"], [0, 30], SPEEDS, [pi.Variant("hinge", failure="hinge")]
    )
    path = tmp_path / "a.h5"
    results = study.run(archive=path, craters=True)
    assert results["hinge"].trajectory is not None and results["hinge"].craters is not None
    archive = pi.Archive(path)
    assert archive.runs() == ["hinge/hinge"]
    assert_same(results["hinge"], archive.results("hinge"))
    back = archive.study()
    assert back.name == study.name and back.variants == study.variants
    assert back.plate_labels == study.plate_labels and back.description == study.description
    assert set(back.scenes.columns) == set(study.scenes.columns)
    for column, values in study.scenes.columns.items():
        np.testing.assert_array_equal(back.scenes.columns[column], values)
    loaded = pi.StudyResults.from_archive(path)
    assert_same(results["hinge"], loaded["hinge"])
    meta = archive.metadata("hinge")
    assert meta["variant"]["failure"] == "hinge" and meta["failure_state_units"] == {
        "finger_angle": "rad"
    }
    assert meta["wall_time_s"] > 0 and meta["versions"]["numpy"] == np.__version__


def test_archive_is_self_describing_in_plain_h5py(tmp_path):
    path = tmp_path / "a.h5"
    small_study().run(archive=path, craters=True)
    datasets = []
    with h5py.File(path, "r") as f:  # no project code from here on
        assert f.attrs["format"] == "plateimpact-archive" and f.attrs["format_version"] == 2
        run = f["t318/runs/plugging"]  # an external link into the run's data file
        assert f["t318/runs"].get("plugging", getlink=True).filename.startswith("a.h5.d/")
        run.visititems(
            lambda name, obj: datasets.append(obj) if isinstance(obj, h5py.Dataset) else None
        )
        assert datasets
        for ds in datasets:
            if (
                ds.dtype.kind == "O"
                or "units" not in ds.attrs
                and ds.name.endswith(("_sample", "_point"))
            ):  # the plate's label; netCDF's dimensions without coordinates
                continue
            assert "units" in ds.attrs and "long_name" in ds.attrs, ds.name
            assert "description" in ds.attrs, ds.name
            assert ds.fletcher32 and ds.chunks is not None, ds.name
        counts = run["trajectory_count"][()]
        assert counts.sum() == run["trajectory_time"].shape[0]
        assert run["crater_count"][()].sum() == run["crater_depth"].shape[0]
        assert run["crater_depth"].attrs["units"] == "m"
        assert run["exit_speed"].attrs["units"] == "m/s"
        assert list(run["outcome"].attrs["flag_values"]) == [1, 2, 3]


def test_runs_append_without_touching_earlier_ones(tmp_path):
    path = tmp_path / "a.h5"
    study = small_study()
    first = study.run(archive=path)
    archive = pi.Archive(path)
    files = {run: archive.data_file(run).read_bytes() for run in archive.runs()}
    index = path.read_bytes()
    # The same study again is refused before it runs: never a silent plugging.2.
    with pytest.raises(pi.ArchiveError, match="already has run t318/plugging: keep it"):
        study.run(archive=path)
    assert path.read_bytes() == index
    again = study.run(archive=path, run_names={"plugging": "plugging-b", "large-pstar": "lp-b"})
    assert archive.runs() == ["t318/plugging", "t318/large-pstar", "t318/plugging-b", "t318/lp-b"]
    for run, data in files.items():  # earlier runs' files are never written again
        assert archive.data_file(run).read_bytes() == data
    assert_same(first["plugging"], again["plugging"])
    assert_same(first["plugging"], archive.results("plugging-b"))
    # overwrite replaces a run atomically; its old data file goes once the index is in.
    old = archive.data_file("t318/plugging")
    study.run(archive=path, overwrite=True)
    assert len(archive.runs()) == 4 and not old.exists()
    assert archive.data_file("t318/plugging") != old
    assert_same(first["plugging"], archive.results("t318/plugging"))
    with pytest.raises(pi.ParameterError, match="give one"):
        study.run(archive=path, overwrite=True, resume=True)
    other = pi.Study.grid("t318", ["2024-T3/1.27"], [0], SPEEDS, [pi.Variant("x")])
    with pytest.raises(pi.ArchiveError, match="different study"):
        other.run(archive=path)


def kill_study(variants: list[pi.Variant]) -> pi.Study:
    return pi.Study.grid("kill", ["2024-T3/3.18"], [0, 45, 60], np.linspace(150.0, 1200.0, 20),
                         variants)  # fmt: skip


def test_killing_the_writer_during_the_second_run_keeps_the_first(tmp_path):
    path = tmp_path / "a.h5"
    run_chunk, calls = plateimpact.run.simulation.run_chunk, [0]

    def chunk(*args, **kwargs):
        calls[0] += 1
        if calls[0] == 5:  # the second run's second chunk of three: killed there, not timed
            os.kill(os.getpid(), signal.SIGKILL)
        return run_chunk(*args, **kwargs)

    def write() -> None:  # in a child forked from this process: its modules untouched here
        plateimpact.run.simulation.run_chunk = chunk
        second = pi.Variant("second", integrator="segment", integrator_settings={"step": 1e-2})
        kill_study([pi.Variant("fast"), second]).run(archive=path, chunk_size=20)

    assert forked(write).returncode == -signal.SIGKILL
    archive = pi.Archive(path)
    assert archive.runs() == ["kill/fast"]
    assert_same(kill_study([pi.Variant("fast")]).run()["fast"], archive.results("kill/fast"))


def test_resume_reads_back_finished_runs_and_runs_the_rest(tmp_path):
    path = tmp_path / "a.h5"
    fast, coarse = pi.Variant("fast"), pi.Variant("coarse", integrator_settings={"rtol": 1e-6})
    speeds = np.linspace(150.0, 1200.0, 6)
    pi.Study.grid("r", ["2024-T3/3.18"], [0, 60], speeds, fast).run(archive=path)
    written = pi.Archive(path).metadata("r/fast")["end_time"]
    study = pi.Study.grid("r", ["2024-T3/3.18"], [0, 60], speeds, [fast, coarse])
    resumed = study.run(archive=path, resume=True)
    archive = pi.Archive(path)
    assert archive.runs() == ["r/fast", "r/coarse"]  # fast was not run again
    assert archive.metadata("r/fast")["end_time"] == written
    assert_same(resumed["fast"], archive.results("r/fast"))
    assert_same(resumed["coarse"], study.run()["coarse"])
    assert study.run(archive=path, resume=True).runs.keys() == {"fast", "coarse"}
    assert archive.runs() == ["r/fast", "r/coarse"]  # nothing left to do
    changed = pi.Variant("fast", integrator_settings={"rtol": 1e-7})  # same name, other model
    with pytest.raises(pi.ArchiveError, match="r/fast with other plug-ins or settings"):
        pi.Study.grid("r", ["2024-T3/3.18"], [0, 60], speeds, changed).run(
            archive=path, resume=True
        )
    with pytest.raises(pi.ParameterError, match="resume"):
        study.run(resume=True)
    with_craters = study.run(archive=path, resume=True, craters=True)  # not kept: run again
    assert with_craters["coarse"].craters is not None
    assert sorted(archive.runs()) == ["r/coarse", "r/fast"]  # replaced, not added
    assert archive.results("r/coarse").craters is not None


HOLD_LOCK = """
import sys
from pathlib import Path
from plateimpact.storage.lock import locked
path = Path(sys.argv[1])
lock = path.with_name(path.name + ".lock")
with locked(path, path, lock, wait=0.0):
    print("locked", flush=True)
    sys.stdin.readline()  # hold the lock until the test closes our stdin
"""


def test_a_live_writer_makes_others_wait_or_save_aside_and_readers_read(tmp_path):
    """A writer holding the lock (another process, holding it until told) does not stop
    readers (the file they open is always whole), makes a writer that cannot wait save
    its run beside the archive and say where, and once it is gone the archive takes
    runs again. A lock file left by a dead writer holds nothing: the kernel let go."""
    path = tmp_path / "a.h5"
    study = small_study()
    results = study.run(archive=path)
    holder = subprocess.Popen(
        [sys.executable, "-c", HOLD_LOCK, str(path)], stdin=subprocess.PIPE, stdout=subprocess.PIPE
    )
    try:
        assert holder.stdout.readline() == b"locked\n"
        assert len(pi.Archive(path).runs()) == 2
        impatient = pi.Archive(path, wait=0.0)
        with pytest.raises(pi.ArchiveError, match=f"process {holder.pid} on .*saved to ") as info:
            impatient.append_run(study, study.variants[0], results["plugging"], {"note": "x"})
        assert "for 0 s (Archive(path, wait=SECONDS) waits longer" in str(info.value)
        side = pathlib.Path(str(info.value).rsplit("saved to ", 1)[1])
        assert side.parent == tmp_path and pi.Archive(side).runs() == ["t318/plugging"]
        assert_same(results["plugging"], pi.Archive(side).results("plugging"))
        assert len(pi.Archive(path).runs()) == 2  # the archive itself untouched
        # A study given such an archive warns per run and still returns its results.
        with pytest.warns(pi.ArchiveWaitWarning, match="saved to ") as warned:
            again = study.run(archive=pi.Archive(path, wait=0.0), overwrite=True)
        assert len(warned) == len(study.variants)
        assert_same(results["plugging"], again["plugging"])
        assert len(pi.Archive(path).runs()) == 2
    finally:
        holder.stdin.close()
        holder.wait()
    # the lock is free again (its file stays, naming the last writer)
    study.run(archive=path, run_names={"plugging": "p2", "large-pstar": "l2"})
    assert len(pi.Archive(path).runs()) == 4


def flip_bytes(path, dataset):
    with h5py.File(path, "r") as f:
        offset = f[dataset].id.get_chunk_info(0).byte_offset
    with open(path, "r+b") as handle:
        handle.seek(offset + 3)
        byte = handle.read(1)
        handle.seek(offset + 3)
        handle.write(bytes([byte[0] ^ 0xFF]))


def test_bad_archives_give_one_line_errors(small_archive, tmp_path, capsys):
    path = shutil.copytree(small_archive.parent, tmp_path / "copy") / "a.h5"
    flip_bytes(pi.Archive(path).data_file("plugging"), "exit_speed")
    with pytest.raises(pi.ArchiveError, match="damaged"):
        pi.Archive(path).results("plugging")
    not_hdf5 = tmp_path / "notes.h5"
    not_hdf5.write_text("not an archive\n")
    cases = [
        (["show", str(not_hdf5)], "is not an HDF5 file"),
        (["show", str(tmp_path / "missing" / "a.h5")], "does not exist"),
        (["compare", str(path), "plugging", "nope"], "no run 'nope'"),
        (["plot", str(path), "--run", "plugging", "--out", str(tmp_path / "x.png")], "damaged"),
    ]
    for argv, message in cases:
        assert cli(argv) == 2
        err = capsys.readouterr().err
        assert message in err and err.count("\n") == 1, err
    with pytest.raises(pi.ArchiveError, match="does not exist"):
        small_study().run(archive=tmp_path / "missing" / "a.h5")


def test_compare_reports_the_large_pstar_outcome_changes(small_archive, capsys):
    path = small_archive
    results = pi.StudyResults.from_archive(path)
    comparison = results.compare("plugging", "large-pstar")
    plugging, intact = results["plugging"].outcome, results["large-pstar"].outcome
    failed = results["plugging"].plate_failed != results["large-pstar"].plate_failed
    np.testing.assert_array_equal(comparison.changed, np.flatnonzero((plugging != intact) | failed))
    # A plate that never fails is never perforated, and fast impacts perforate it otherwise.
    assert not np.any(intact == pi.Outcome.PERFORATION)
    assert comparison.summary()["changes"]["perforation -> embedment"] > 0
    assert cli(["compare", str(path), "plugging", "large-pstar"]) == 0
    out = capsys.readouterr().out
    assert f"{comparison.changed.size} with another outcome" in out
    assert "perforation -> embedment" in out  # in ranges: tests/test_compare.py


def test_plot_and_show_from_an_archive(small_archive, tmp_path, capsys):
    path = small_archive
    png = tmp_path / "p.png"
    runs = ["--run", "plugging", "--run", "large-pstar"]
    assert cli(["plot", str(path), *runs, "--out", str(png), "--dpi", "50"]) == 0  # a PNG
    assert png.read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"
    assert cli(["show", str(path)]) == 0
    out = capsys.readouterr().out
    assert "t318/plugging" in out and "t318/large-pstar" in out and "48 scenes" in out


def test_archived_craters_are_the_sections_of_the_archived_paths(tmp_path):
    """Each stored section is the one eqs 31-39 give for the stored path, and its deepest
    point is the sphere's deepest point (max P), or the back surface where it was holed."""
    path = tmp_path / "a.h5"
    study = pi.Study.grid(
        "c", ["6061-T6/9.53", "2024-T3/3.18"], [0, 60], SPEEDS, pi.Variant("default")
    )
    in_memory = study.run(archive=path, craters=True, chunk_size=5)["default"]
    assert_same(study.run(craters=True)["default"], in_memory)  # chunks concatenate exactly
    result = pi.Archive(path).results("default")
    assert_same(in_memory, result)
    scenes = study.scenes
    holed = 0
    for i in range(len(result)):
        section = result.crater_of(i)
        expected = crater_section(
            result.trajectory_of(i), scenes.radius[i], thickness=scenes.thickness[i]
        )
        np.testing.assert_array_equal(section.depth, expected.depth)
        np.testing.assert_array_equal(section.lateral, expected.lateral)
        assert section.impact_point == expected.impact_point
        deepest = min(result.max_penetration[i], scenes.thickness[i])
        assert section.max_depth == pytest.approx(deepest, rel=1e-12), i
        holed += section.max_depth == scenes.thickness[i]
    assert holed == np.count_nonzero(result.outcome == pi.Outcome.PERFORATION)
    part = result.take(np.array([3, 0]))
    np.testing.assert_array_equal(part.crater_of(1).depth, result.crater_of(0).depth)


def test_trajectory_and_crater_plots_from_an_archive(small_archive, tmp_path, capsys):
    path = tmp_path / "a.h5"
    study = pi.Study.grid("c", ["2024-T3/3.18"], [0, 60], SPEEDS, pi.Variant("default"))
    study.run(archive=path, craters=True)
    for kind in ("crater", "trajectory"):
        png = tmp_path / f"{kind}.png"
        args = ["plot", str(path), "--run", "default", "--kind", kind, "--out", str(png)]
        args += ["--dpi", "50"]  # a PNG, whatever its pixels
        assert cli([*args, "--speed", "300", "--speed", "900"]) == 0
        assert png.read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"
    assert cli(["show", str(path)]) == 0
    assert "with trajectories and craters" in capsys.readouterr().out
    bare = small_archive
    out = str(tmp_path / "x.png")
    assert cli(["plot", str(bare), "--run", "plugging", "--kind", "crater", "--out", out]) == 2
    err = capsys.readouterr().err.strip()
    assert "craters=True" in err and "\n" not in err
    args = ["plot", str(path), "--run", "default", "--kind", "crater", "--out", out]
    assert cli([*args, "--speed", "nan"]) == 2
    assert "--speed" in capsys.readouterr().err


def test_a_local_dask_cluster_gives_the_in_process_results(tmp_path):
    distributed = pytest.importorskip("distributed")
    study = small_study()
    local = study.run()
    # One worker process: every chunk goes to it and back pickled, as to any worker; the
    # results come back in the order the chunks were sent (run.simulation.run_in_chunks),
    # so a second worker would change only which process ran a chunk, and when
    with (
        distributed.LocalCluster(
            n_workers=1, threads_per_worker=1, processes=True, dashboard_address=None
        ) as cluster,
        distributed.Client(cluster) as client,
    ):
        spread = study.run(executor=client.get_executor(), chunk_size=10, archive=tmp_path / "d.h5")
    for name in local.runs:
        assert_same(local[name], spread[name])
        assert_same(local[name], pi.Archive(tmp_path / "d.h5").results(name))


def test_reproduce_writes_one_archive_and_a_figure_per_family(quick_report, tmp_path, capsys):
    # reproduce --quick: the whole job (every study, variant, map and experiment tool)
    # through the same code as the full one, on small grids, once per session
    out = tmp_path / "report"
    shutil.copytree(quick_report, out)
    archive = pi.Archive(out / "report.h5")
    assert len(archive.studies()) == 6  # five figure families and the craters of 35-37
    assert len(archive.runs()) == 8  # two comparison families run two variants each
    assert archive.results("craters_60deg/default").craters is not None
    maps = [f"map_{plate.replace('/', '_')}" for plate in pi.presets.PLATES]
    assert stored_limits(out / "report.h5") == maps  # and the five plates' outcome maps
    pngs = sorted(out.glob("*.png"))  # and the experiment's validate and V50 figures
    assert len(pngs) == 11 and all(p.read_bytes()[:4] == b"\x89PNG" for p in pngs)
    table = (out / "pstar_table_SAE1010_1.47mm.csv").read_text().splitlines()
    assert table[0].startswith("obliquity_deg,ricochet_pstar_mm,perforation_pstar_mm")
    for family in ("6061-T6_9.53mm", "SAE1010_1.47mm"):  # a journal page, 7.2 in at 50 dpi
        assert (out / f"{family}.png").read_bytes()[16:20] == (360).to_bytes(4, "big")
    # Everything is there: the figures again, as PDF.
    capsys.readouterr()
    assert cli(["reproduce", "--quick", "--out", str(out), "--resume", "--format", "pdf"]) == 0
    assert str(out / "report.h5") in capsys.readouterr().out
    pdfs = sorted(out.glob("*.pdf"))
    assert [p.stem for p in pdfs] == [p.stem for p in pngs]
    assert all(p.read_bytes()[:5] == b"%PDF-" for p in pdfs)
    assert len(pi.Archive(out / "report.h5").runs()) == 8
    assert stored_limits(out / "report.h5") == maps  # read back, not stored twice
    assert cli(["reproduce", "--out", str(tmp_path / "missing" / "report")]) == 2
