"""Faults that must not lose or hide work (issue 21): libhdf5 never writes to a disk (a
full one is a plain one-line error, never a crash), an upgrade holds the lock and
completes when rerun after a kill at any stage, and names too long or a read-only
filesystem are one line naming the flag, before any work. Kills are deterministic:
a forked writer SIGKILLs itself at a named fault point (forking.forked)."""

from __future__ import annotations

import ast
import errno
import os
import shutil
import signal
import subprocess
from pathlib import Path

import h5py
import numpy as np
import pytest
import xarray as xr
from forking import forked
from test_archive import assert_same
from test_output_files import assert_one_line, mounted, run_cli
from test_output_flags import CALIBRATE, SCENE

import plateimpact as pi
from plateimpact import limits, presets
from plateimpact.cli.commands import reproduce as archive_commands
from plateimpact.storage import upgrade as upgrading
from plateimpact.storage.export import declared_column, netcdf_bytes
from plateimpact.storage.lock import ArchiveBusyError, locked
from plateimpact.storage.netcdf import write_run_file

FORMAT1 = Path(__file__).parent / "data" / "format1.h5"
UPGRADE_STAGES = ("run", "record", "built", "kept", "replaced")


def tiny_study(variant: str = "v") -> pi.Study:
    return pi.Study.grid("w", ["2024-T3/3.18"], [0, 45], np.array([300.0, 900.0]),
                         pi.Variant(variant))  # fmt: skip


@pytest.fixture(scope="module")
def found() -> limits.Limits:
    return limits.along_speed(
        pi.Simulation.from_names(), presets.DEFAULT_SPHERE, presets.plate("2024-T3/3.18"),
        np.radians([30.0]), (200.0, 800.0), resolution=100.0,
    )  # fmt: skip


# -- libhdf5 never writes to a disk --------------------------------------------------------


def test_libhdf5_never_writes_to_a_disk(tmp_path, monkeypatch, found):
    """Every archive file (index, runs, scenes, records, exports, upgrades) is made in
    memory and written by the atomic writer: h5py never opens a name to write."""
    opened: list[tuple[object, str]] = []
    init = h5py.File.__init__

    def watched(self, name, mode="r", *args, **kwargs):
        if mode != "r" and not hasattr(name, "write"):
            opened.append((name, mode))
        init(self, name, mode, *args, **kwargs)

    monkeypatch.setattr(h5py.File, "__init__", watched)
    path = tmp_path / "a.h5"
    tiny_study().run(archive=path, record_trajectory=True)
    tiny_study().run(archive=path, overwrite=True)
    limits.archive_limits(path, "l", found)
    netcdf_bytes(pi.Archive(path), "v", registry=pi.default_registry())
    old = tmp_path / "old.h5"
    shutil.copyfile(FORMAT1, old)
    upgrading.upgrade(old, registry=pi.default_registry())
    assert opened == []


def test_a_data_file_made_in_memory_reads_as_one_written_to_a_path(tmp_path):
    """The run's file is what h5netcdf writes to a path, for xarray: same variables,
    values, dimensions and attributes (the bytes differ only in HDF5's free-space
    layout: a file object is allocated without the disk driver's aggregation)."""
    study = tiny_study()
    path = tmp_path / "a.h5"
    result = study.run(archive=path, craters=True)["v"]
    archive = pi.Archive(path)
    attributes = archive.raw_attributes("v")
    on_disk = tmp_path / "direct.nc"
    declared = {k: declared_column(k, pi.default_registry()) for k in study.scenes.columns}
    write_run_file(on_disk, study.scenes.columns, declared, study.plate_labels, result,
                   {"study": "w", "run": "v", **attributes})  # fmt: skip
    with (xr.open_dataset(archive.data_file("v"), engine="h5netcdf") as ours,
          xr.open_dataset(on_disk, engine="h5netcdf") as direct):  # fmt: skip
        xr.testing.assert_identical(ours, direct)


def fill_and_write(disk: Path, found: limits.Limits) -> None:
    """On ``disk`` filled to within 0-40 KiB of full, each kind of write: a line each of
    what happened (mode, bytes left, the archive's bytes unchanged, runs readable at its
    path, the error's text or ''). The archive each append and limits starts from is
    written once, beside the disk, and copied onto it (index, data files and lock)."""
    start = disk.parent / "start"
    start.mkdir()
    tiny_study().run(archive=start / "a.h5")
    for mode in ("append", "limits", "upgrade"):
        for left in (0, 8192, 12288, 20480, 40960):
            for entry in disk.iterdir():  # the last case's archive and filler
                if entry.is_dir():
                    shutil.rmtree(entry)
                else:
                    entry.unlink()
            archive = disk / "a.h5"
            if mode == "upgrade":
                shutil.copyfile(FORMAT1, archive)
            else:
                shutil.copytree(start, disk, dirs_exist_ok=True)
            before = archive.read_bytes()
            free = os.statvfs(disk).f_bavail * os.statvfs(disk).f_frsize
            with open(disk / "filler", "wb") as filler:
                filler.write(bytes(max(free - left, 0)))
            try:
                if mode == "append":
                    tiny_study("x").run(archive=archive, record_trajectory=True)
                elif mode == "limits":
                    limits.archive_limits(archive, "l", found)
                else:
                    upgrading.upgrade(archive, registry=pi.default_registry())
                error = ""
            except pi.ArchiveError as exc:
                error = str(exc)
            same = archive.read_bytes() == before
            print(mode, left, same, pi.Archive(archive).runs() != [], repr(error), flush=True)


def test_a_full_disk_at_any_fill_is_one_line_and_keeps_the_archive(tmp_path, found):
    """Appends, stored limits and upgrades on a disk filled to within 0-40 KiB, where
    libhdf5's own writes used to crash the process (exit 139 after 90 lines of
    tracebacks; an upgrade left the archive's path empty): a one-line ArchiveError and
    the archive as it was, or the work done. (In a forked child: a crash is a result,
    and what libhdf5 prints is in its stderr.)"""
    with mounted(tmp_path, "size=512k") as disk:
        done = forked(lambda: fill_and_write(disk, found))
        assert done.returncode == 0, done.stderr[-3000:]
        lines = done.stdout.splitlines()
        assert len(lines) == 15 and not done.stderr, done.stdout + done.stderr[-3000:]
        for line in lines:
            mode, left, same, readable, error = line.split(" ", 4)
            error = ast.literal_eval(error)
            assert readable == "True", line  # an archive at the path, whatever happened
            if error:
                assert same == "True" and "\n" not in error, line
                assert "No space left on device" in error and "unchanged" in error, line
        assert any(ast.literal_eval(line.split(" ", 4)[4]) for line in lines)  # it filled


def test_an_export_needs_no_temporary_directory(tmp_path, monkeypatch):
    path = tmp_path / "a.h5"
    tiny_study().run(archive=path)
    monkeypatch.setattr("tempfile.tempdir", str(tmp_path / "nowhere"))  # not even there
    target = tmp_path / "v.nc"
    code, _, err = run_cli(["export", str(path), "--run", "v", "--to", str(target)])
    assert code == 0, err
    with xr.open_dataset(target, engine="h5netcdf") as ds:
        np.testing.assert_array_equal(
            ds["exit_speed"].values, pi.Archive(path).results("v").exit_speed
        )


# -- upgrade: under the lock, and completed when rerun after a kill -------------------------


def test_an_upgrade_waits_for_the_archives_writer(tmp_path):
    path = tmp_path / "old.h5"
    shutil.copyfile(FORMAT1, path)
    archive = pi.Archive(path)
    with locked(archive.path, archive.real, archive.lock_path, 1.0):
        with pytest.warns(pi.ArchiveWaitWarning, match="waiting for it"):
            with pytest.raises(ArchiveBusyError, match="stayed busy"):
                upgrading.upgrade(path, wait=0.0, registry=pi.default_registry())
    assert path.read_bytes() == FORMAT1.read_bytes() and not archive.data.exists()
    assert not upgrading.backup_path(path).exists()


def _killed_at(stage: str, path: Path, nth: int = 1) -> int:
    """The returncode of a writer (forked from this process) that upgrades ``path`` and
    SIGKILLs itself at the ``nth`` call of the fault point ``stage``."""
    calls = [0]

    def die(where: str) -> None:
        calls[0] += where == stage
        if where == stage and calls[0] == nth:
            os.kill(os.getpid(), signal.SIGKILL)

    def upgrade() -> None:
        upgrading.fault_point = die  # the child's module: this process's is untouched
        upgrading.upgrade(path, registry=pi.default_registry())

    return forked(upgrade).returncode


@pytest.mark.parametrize("stage", UPGRADE_STAGES)
def test_an_upgrade_killed_at_any_stage_leaves_an_archive_and_a_rerun_completes(tmp_path, stage):
    path = tmp_path / "old.h5"
    shutil.copyfile(FORMAT1, path)
    original = pi.Archive(FORMAT1)
    returncode = _killed_at(stage, path, nth=2 if stage == "run" else 1)  # "run": 2 runs of 3
    assert returncode == -signal.SIGKILL
    assert pi.Archive(path).runs() == original.runs()  # an archive at the path, whole
    if stage != "replaced":
        assert pi.Archive(path).version() == 1 and path.read_bytes() == FORMAT1.read_bytes()
        kept = upgrading.upgrade(path, registry=pi.default_registry())
    else:
        code, _, err = run_cli(["upgrade", str(path)])
        assert_one_line(code, err, "nothing to upgrade")
        kept = upgrading.backup_path(path)
    new = pi.Archive(path)
    assert kept.read_bytes() == FORMAT1.read_bytes() and new.version() == 2
    assert new.runs() == original.runs()
    for run in original.runs():
        assert_same(original.results(run), new.results(run))
        assert new.metadata(run) == original.metadata(run)
    assert new.record("l").attributes == original.record("l").attributes
    names = {p.name for p in new.data.iterdir()}
    assert len(names) == 3 + 1 + 1  # the runs, the study's scenes, the record: no orphan
    assert not [p for p in tmp_path.iterdir() if p.name.endswith(".tmp")]


@pytest.mark.parametrize("stage", UPGRADE_STAGES[:-1])
def test_an_upgrade_that_fails_at_any_stage_keeps_the_format_1_archive(
    tmp_path, stage, monkeypatch
):
    path = tmp_path / "old.h5"
    shutil.copyfile(FORMAT1, path)

    def full_disk(where: str) -> None:
        if where == stage:
            raise OSError(errno.ENOSPC, os.strerror(errno.ENOSPC))

    monkeypatch.setattr(upgrading, "fault_point", full_disk)
    code, _, err = run_cli(["upgrade", str(path)])
    assert_one_line(code, err, "No space left on device", "unchanged")
    assert path.read_bytes() == FORMAT1.read_bytes()
    data = pi.Archive(path).data  # the new data files removed again
    assert not data.exists() or not any(data.iterdir())
    if stage == "kept":  # the next upgrade completes (after the hard link is made)
        monkeypatch.undo()
        assert run_cli(["upgrade", str(path)])[0] == 0 and pi.Archive(path).version() == 2


def test_an_upgrade_where_hard_links_are_not_allowed_keeps_a_copy(tmp_path, monkeypatch):
    path = tmp_path / "old.h5"
    shutil.copyfile(FORMAT1, path)

    def no_links(*args, **kwargs):
        raise OSError(errno.EPERM, os.strerror(errno.EPERM))

    monkeypatch.setattr(os, "link", no_links)
    kept = upgrading.upgrade(path, registry=pi.default_registry())
    assert kept.read_bytes() == FORMAT1.read_bytes() and pi.Archive(path).version() == 2


# -- names too long, paths too long, read-only filesystems ---------------------------------


def _no_run(*args, **kwargs):
    raise AssertionError("work started before the archive was refused")


def test_an_archive_whose_temporaries_would_not_fit_is_refused_first(tmp_path, monkeypatch):
    monkeypatch.setattr("plateimpact.run.simulation.run_chunk", _no_run)
    for length, words in [(240, "NAME_MAX"), (300, "NAME_MAX")]:
        path = tmp_path / ("x" * (length - 3) + ".h5")
        with pytest.raises(pi.ArchiveError, match=words):
            tiny_study().run(archive=path)
    assert sorted(os.listdir(tmp_path)) == []


@pytest.fixture(scope="module")
def deep(tmp_path_factory) -> Path:
    """A directory whose path is over 5,000 bytes (made a level at a time)."""
    top = tmp_path_factory.mktemp("deep")
    fd = os.open(top, os.O_RDONLY | os.O_DIRECTORY)
    parts = ["d" * 200] * 25
    try:
        for part in parts:
            os.mkdir(part, dir_fd=fd)
            inner = os.open(part, os.O_RDONLY | os.O_DIRECTORY, dir_fd=fd)
            os.close(fd)
            fd = inner
    finally:
        os.close(fd)
    return top.joinpath(*parts)


def test_a_path_over_path_max_is_one_line_from_the_api(deep, monkeypatch):
    monkeypatch.setattr("plateimpact.run.simulation.run_chunk", _no_run)
    with pytest.raises(pi.ArchiveError, match="PATH_MAX"):
        tiny_study().run(archive=deep / "a.h5")
    with pytest.raises(pi.ArchiveError, match="PATH_MAX"):
        pi.Archive(deep / "a.h5").runs()


@pytest.fixture(scope="module")
def small_archive(tmp_path_factory) -> Path:
    path = tmp_path_factory.mktemp("small") / "a.h5"
    tiny_study().run(archive=path)
    return path


# (name, command line with TARGET for the file or directory the command writes, the flag
# naming it in messages (None: the positional archive), the target's suffix)
WRITERS = [
    ("run", ["run", *SCENE, "--trajectory", "TARGET"], "--trajectory", ".csv"),
    ("sweep", ["sweep", "--preset", "2024-T3/3.18", "--speeds", "300", "--obliquities", "0",
               "--csv", "TARGET"], "--csv", ".csv"),
    ("calibrate", [*CALIBRATE, "--out", "TARGET"], "--out", ".json"),
    ("limits", ["limits", "--preset", "2024-T3/3.18", "--obliquities", "0", "--archive",
                "TARGET"], "--archive", ".h5"),
    ("map", ["map", "--preset", "2024-T3/3.18", "--speeds", "100:900:3", "--obliquities",
             "0,45", "--png", "PNG", "--archive", "TARGET"], "--archive", ".h5"),
    ("export", ["export", "ARCHIVE", "--run", "v", "--to", "TARGET"], "--to", ".nc"),
    ("reproduce", ["reproduce", "--out", "TARGET"], "--out", ""),
    ("upgrade", ["upgrade", "TARGET"], None, ".h5"),
]  # fmt: skip


def _argv(argv: list[str], target: Path, archive: Path, png: Path) -> list[str]:
    swap = {"TARGET": str(target), "ARCHIVE": str(archive), "PNG": str(png)}
    return [swap.get(a, a) for a in argv]


@pytest.fixture
def no_reproduce(monkeypatch):
    """reproduce must refuse before it runs anything: running is a failure here."""
    monkeypatch.setattr(archive_commands, "study_collection", lambda name: _no_run)


@pytest.mark.parametrize(("name", "argv", "flag", "suffix"), WRITERS, ids=[w[0] for w in WRITERS])
@pytest.mark.parametrize("too_long", ["name", "path"])
def test_names_and_paths_too_long_are_one_line_naming_the_flag(
    name, argv, flag, suffix, too_long, tmp_path, deep, small_archive, no_reproduce
):
    if too_long == "name":
        target = tmp_path / ("x" * 300 + suffix)
        words = ["255"]
    else:
        target = deep / f"x{suffix}"
        words = ["PATH_MAX"]
    if name == "upgrade" and too_long == "path":
        pytest.skip("a file to upgrade cannot be made at a path over PATH_MAX")
    code, _, err = run_cli(_argv(argv, target, small_archive, tmp_path / "m.png"))
    assert_one_line(code, err, *(words + ([flag] if flag else [])))


@pytest.fixture(scope="module")
def read_only(tmp_path_factory) -> Path:
    """A read-only filesystem holding a format-1 archive (root only)."""
    with mounted(tmp_path_factory.mktemp("ro"), "size=2m") as disk:
        shutil.copyfile(FORMAT1, disk / "old.h5")
        done = subprocess.run(["mount", "-o", "remount,ro", str(disk)], capture_output=True)
        if done.returncode != 0:
            pytest.skip(f"cannot remount read-only: {done.stderr.decode().strip()}")
        yield disk


@pytest.mark.parametrize(("name", "argv", "flag", "suffix"), WRITERS, ids=[w[0] for w in WRITERS])
def test_a_read_only_filesystem_is_one_line_naming_the_flag(
    name, argv, flag, suffix, read_only, tmp_path, small_archive, no_reproduce
):
    target = read_only / ("old.h5" if name == "upgrade" else f"new{suffix}")
    code, _, err = run_cli(_argv(argv, target, small_archive, tmp_path / "m.png"))
    assert_one_line(code, err, "read-only", *([flag] if flag else []))


def test_study_run_on_a_read_only_filesystem_is_one_line(read_only, monkeypatch):
    monkeypatch.setattr("plateimpact.run.simulation.run_chunk", _no_run)
    with pytest.raises(pi.ArchiveError, match="read-only"):
        tiny_study().run(archive=read_only / "a.h5")
