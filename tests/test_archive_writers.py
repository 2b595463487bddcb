"""Archive writers: never a lost run, never a replaced file, never a second writer; failures
injected deterministically at each stage of an append (storage.append.fault_point).

Writers that must be other processes (killed, or racing this one for the lock) are forked
from this one (:class:`forking.Forked`): as separate as a subprocess, without the second of CPU a
new interpreter spends importing plateimpact."""

from __future__ import annotations

import math
import os
import shutil
import signal
import stat
import threading
from collections.abc import Callable
from pathlib import Path

import h5py
import numpy as np
import pytest
from forking import Forked, forked
from test_output_files import assert_one_line, mounted, run_cli

import plateimpact as pi
from plateimpact.storage import append as appending

STAGES = ("copy", "write", "flush", "fsync", "replace")


def tiny_study(name: str = "w") -> pi.Study:
    return pi.Study.grid(name, ["2024-T3/3.18"], [0, 45], np.array([300.0, 900.0]), pi.Variant("v"))


@pytest.fixture(scope="module")
def tiny_result() -> pi.BatchResult:
    return tiny_study().run()["v"]


def archive_maker(start: Path) -> Callable[[Path], bytes]:
    """The tiny study's archive (run w/v) written once into the directory ``start``;
    the function returned copies it to a path (named a.h5, as it is) with its data
    directory and lock file and returns the index's bytes (what writer tests test is
    what writers do to an archive, not its first write: tests/test_archive.py)."""
    tiny_study().run(archive=start / "a.h5")

    def make(path: Path) -> bytes:
        assert path.name == "a.h5", path
        shutil.copytree(start, path.parent, dirs_exist_ok=True)
        return path.read_bytes()

    return make


@pytest.fixture(scope="module")
def make_archive(tmp_path_factory) -> Callable[[Path], bytes]:
    return archive_maker(tmp_path_factory.mktemp("start"))


def debris(directory: Path) -> list[str]:
    """Temporaries in ``directory``, and in each archive's data directory temporaries and
    data files its index does not name (read with h5py alone)."""
    found = [p.name for p in directory.iterdir() if p.name.endswith(".tmp")]
    for data in directory.glob("*.d"):
        links: list[object] = []
        index = data.with_suffix("")
        if index.exists():
            with h5py.File(index, "r") as f:
                f.visititems_links(lambda _, link, into=links: into.append(link))
        named = {link.filename for link in links if isinstance(link, h5py.ExternalLink)}
        found += [
            f"{data.name}/{p.name}"
            for p in data.iterdir()
            if p.name.endswith(".tmp") or f"{data.name}/{p.name}" not in named
        ]
    return sorted(found)


@pytest.mark.parametrize("stage", STAGES)
def test_a_failed_append_leaves_the_archive_as_it_was(
    tmp_path, stage, monkeypatch, tiny_result, make_archive
):
    path = tmp_path / "a.h5"
    before = make_archive(path)

    def fail(where: str) -> None:
        if where == stage:
            raise OSError(28, "No space left on device")

    monkeypatch.setattr(appending, "fault_point", fail)
    study = tiny_study()
    with pytest.raises(OSError, match="No space left"):
        pi.Archive(path).append_run(study, pi.Variant("x"), tiny_result, {"variant": "{}"})
    assert path.read_bytes() == before and debris(tmp_path) == []
    monkeypatch.undo()
    pi.Archive(path).append_run(study, pi.Variant("x"), tiny_result, {"note": "next"})
    assert set(pi.Archive(path).runs()) == {"w/v", "w/x"}  # and the lock was let go


def killed_appender(path: Path, stage: str, result: pi.BatchResult) -> int:
    """The returncode of a forked writer that appends ``result`` to ``path`` as run
    ``killed`` and SIGKILLs itself at the fault point ``stage``."""

    def die(where: str) -> None:
        if where == stage:
            os.kill(os.getpid(), signal.SIGKILL)

    def append() -> None:
        appending.fault_point = die  # the child's module: this process's is untouched
        pi.Archive(path).append_run(tiny_study(), pi.Variant("killed"), result, {"note": "x"})

    return forked(append).returncode


@pytest.mark.parametrize("stage", STAGES)
def test_an_appender_killed_at_any_stage_keeps_every_finished_run(
    tmp_path, stage, tiny_result, make_archive
):
    path = tmp_path / "a.h5"
    before = make_archive(path)
    assert killed_appender(path, stage, tiny_result) == -signal.SIGKILL
    assert path.read_bytes() == before and pi.Archive(path).runs() == ["w/v"]
    # Killed once its data file was complete, it leaves that file unnamed by the index:
    # no reader sees it, and the next writer removes it.
    orphans = [p for p in debris(tmp_path) if p.endswith(".nc")]
    assert len(orphans) == (stage in ("flush", "fsync", "replace"))
    pi.Archive(path).append_run(tiny_study(), pi.Variant("next"), tiny_result, {"note": "x"})
    assert set(pi.Archive(path).runs()) == {"w/v", "w/next"} and debris(tmp_path) == []


def test_a_failure_letting_go_of_the_lock_keeps_the_run_says_so_and_frees_the_lock(
    tmp_path, monkeypatch, tiny_result, make_archive
):
    path = tmp_path / "a.h5"
    make_archive(path)

    def fail(where: str) -> None:
        if where == "unlock":
            raise OSError(5, "Input/output error")

    monkeypatch.setattr(appending, "fault_point", fail)
    study = tiny_study()
    with pytest.raises(pi.ArchiveError, match="run w/x was added, then letting go of the lock"):
        pi.Archive(path).append_run(study, pi.Variant("x"), tiny_result, {"note": "x"})
    monkeypatch.undo()
    assert set(pi.Archive(path).runs()) == {"w/v", "w/x"} and debris(tmp_path) == []
    impatient = pi.Archive(path, wait=0.0)  # a lock still held would send this run aside
    impatient.append_run(study, pi.Variant("y"), tiny_result, {"note": "y"})
    assert set(pi.Archive(path).runs()) == {"w/v", "w/x", "w/y"}


def test_an_appender_killed_holding_the_lock_after_its_run_is_in_keeps_it(
    tmp_path, tiny_result, make_archive
):
    path = tmp_path / "a.h5"
    make_archive(path)
    assert killed_appender(path, "unlock", tiny_result) == -signal.SIGKILL
    assert set(pi.Archive(path).runs()) == {"w/v", "w/killed"}
    np.testing.assert_array_equal(
        pi.Archive(path).results("killed").exit_speed, tiny_result.exit_speed
    )
    impatient = pi.Archive(path, wait=0.0)  # the kernel let go of the dead writer's flock
    impatient.append_run(tiny_study(), pi.Variant("next"), tiny_result, {"note": "x"})
    assert len(pi.Archive(path).runs()) == 3 and debris(tmp_path) == []


@pytest.mark.filterwarnings("ignore::plateimpact.base.errors.ArchiveWaitWarning")
def test_eight_threads_and_four_processes_lose_no_run(tmp_path, tiny_result, make_archive):
    path = tmp_path / "a.h5"
    link = tmp_path / "link.h5"
    make_archive(path)
    link.symlink_to(path)  # half the threads write through a link: one lock, one file
    study = tiny_study()

    def racer(p: int) -> None:
        for k in range(3):  # waiting as long as it takes: no clock decides where a run goes
            archive = pi.Archive(path, wait=math.inf)
            archive.append_run(study, pi.Variant(f"p{p}r{k}"), tiny_result, {"n": k})

    # forked before the threads start: a fork copies no lock another thread holds
    processes = [Forked(lambda p=p: racer(p)) for p in range(4)]
    errors: list[BaseException] = []

    def appender(t: int) -> None:
        try:
            for k in range(3):
                archive = pi.Archive(link if t % 2 else path, wait=math.inf)
                archive.append_run(study, pi.Variant(f"t{t}r{k}"), tiny_result, {"n": k})
        except BaseException as exc:  # noqa: BLE001 (reported below)
            errors.append(exc)

    threads = [threading.Thread(target=appender, args=(t,)) for t in range(8)]
    for thread in threads:
        thread.start()
    for thread in threads:
        thread.join()
    ended = [p.wait() for p in processes]
    assert [p.returncode for p in ended] == [0, 0, 0, 0], [p.stderr for p in ended]
    assert errors == []
    runs = pi.Archive(path).runs()
    expected = {f"w/t{t}r{k}" for t in range(8) for k in range(3)}
    expected |= {f"w/p{p}r{k}" for p in range(4) for k in range(3)}
    assert set(runs) == expected | {"w/v"} and len(runs) == 37
    for run in runs:
        np.testing.assert_array_equal(
            pi.Archive(path).results(run).exit_speed, tiny_result.exit_speed
        )
    assert link.is_symlink() and debris(tmp_path) == []


@pytest.mark.parametrize("wait", [-1.0, math.nan, "300", None, True])
def test_a_wait_that_is_no_number_of_seconds_is_refused(tmp_path, wait):
    with pytest.raises(pi.ParameterError, match=r"wait must be a number of seconds >= 0"):
        pi.Archive(tmp_path / "a.h5", wait=wait)


def test_an_archive_and_an_output_keep_their_owner(tmp_path, make_archive):
    if os.geteuid() != 0:
        pytest.skip("giving a file to another user needs root")
    path, csv = tmp_path / "a.h5", tmp_path / "s.csv"
    make_archive(path)
    csv.write_text("old\n")
    for owned in (path, csv):
        os.chown(owned, 65534, 65534)  # nobody's
    tiny_study().run(archive=path, run_names={"v": "again"})
    code, _, err = run_cli(["sweep", "--preset", "2024-T3/3.18", "--speeds", "300",
                            "--obliquities", "0", "--csv", str(csv)])  # fmt: skip
    assert code == 0, err
    for owned in (path, csv):
        assert (owned.stat().st_uid, owned.stat().st_gid) == (65534, 65534), owned
    assert len(pi.Archive(path).runs()) == 2 and csv.read_text().startswith("preset,")


def test_an_archive_keeps_its_mode_and_group_and_a_read_only_one_is_refused(
    tmp_path, tiny_result, make_archive
):
    path = tmp_path / "a.h5"
    make_archive(path)
    path.chmod(0o640)
    os.chown(path, -1, os.getgid())
    tiny_study().run(archive=path, overwrite=True)
    assert stat.S_IMODE(path.stat().st_mode) == 0o640 and path.stat().st_gid == os.getgid()
    new_data = pi.Archive(path).data_file("v")  # a new data file takes the index's mode
    assert new_data is not None and stat.S_IMODE(new_data.stat().st_mode) == 0o640
    path.chmod(0o444)
    before = path.read_bytes()
    with pytest.raises(pi.ArchiveError, match="read-only; refusing to append"):
        tiny_study().run(archive=path, overwrite=True)
    assert path.read_bytes() == before


def test_an_archive_of_another_format_version_is_refused(tmp_path, make_archive):
    path = tmp_path / "a.h5"
    make_archive(path)
    with h5py.File(path, "a") as f:
        f.attrs["format_version"] = 99
    before = path.read_bytes()
    for argv in (["show", str(path)], ["compare", str(path), "v", "v"]):
        code, _, err = run_cli(argv)
        assert_one_line(code, err, "format version 99", "reads versions 1, 2")
    with pytest.raises(pi.ArchiveError, match="format version 99"):
        tiny_study().run(archive=path)
    assert path.read_bytes() == before


def test_a_group_without_its_seal_is_damaged(tmp_path, make_archive):
    path = tmp_path / "a.h5"
    make_archive(path)
    with h5py.File(path, "a") as f:
        del f["w/runs/v"].attrs["attributes_sha256"]
    code, _, err = run_cli(["show", str(path)])
    assert_one_line(code, err, "digest is missing")


@pytest.mark.parametrize("name", ["a\0b", "tab\there", "line\nbreak", "a/b", " padded", ""])
def test_names_that_would_not_survive_hdf5_are_refused(name):
    with pytest.raises(pi.ParameterError, match="printable name"):
        tiny_study(name)
    with pytest.raises(pi.ParameterError, match="printable name"):
        pi.Variant(name)


def test_an_archive_in_a_read_only_place_is_one_line(tmp_path):
    with mounted(tmp_path, "size=64k,ro") as disk:
        with pytest.raises(pi.ArchiveError, match="not writable|Read-only"):
            tiny_study().run(archive=disk / "a.h5")


@pytest.mark.parametrize(
    ("argument", "words"),
    [("", "give an archive file name, got ''"), (".", "not a file"), ("/", "not a file")],
)
def test_show_of_what_is_not_an_archive_file_is_one_line(argument, words, tmp_path, monkeypatch):
    monkeypatch.chdir(tmp_path)
    code, _, err = run_cli(["show", argument])
    assert_one_line(code, err, words)


def test_a_full_disk_during_an_append_keeps_the_archive_and_is_one_line(tmp_path, make_archive):
    with mounted(tmp_path, "size=256k") as disk:
        path = disk / "a.h5"
        before = make_archive(path)
        data = sorted(pi.Archive(path).data.iterdir())
        free = os.statvfs(disk).f_bavail * os.statvfs(disk).f_frsize
        (disk / "filler").write_bytes(b"\0" * (free - 8192))
        big = pi.Study.grid("w", ["2024-T3/3.18"], [0, 45], np.array([300.0, 900.0]),
                            pi.Variant("big"))  # fmt: skip
        with pytest.raises(pi.ArchiveError, match="No space left on device.*unchanged"):
            big.run(archive=path, record_trajectory=True)
        assert path.read_bytes() == before and debris(disk) == []
        assert sorted(pi.Archive(path).data.iterdir()) == data
