"""Every output flag of every command goes through the one atomic writer (issue 15): a
symlink is followed and its target keeps its mode, what is not a regular file is never
replaced, and a full disk at any flag keeps the old file. Faults are injected at the
writer's named stages (storage.output.fault_point), never by timing."""

from __future__ import annotations

import errno
import os
import shutil
import stat
from pathlib import Path

import numpy as np
import pytest
from test_output_files import assert_one_line, run_cli

import plateimpact as pi
from plateimpact.storage import append as appending
from plateimpact.storage import output

SHOTS = Path(__file__).resolve().parents[1] / "studies" / "data" / "shots_2024T3_3.18mm.csv"
GONOGO = SHOTS.with_name("gonogo_SAE1010_1.47mm.csv")
SCENE = ["--preset", "2024-T3/3.18", "--speed", "500", "--obliquity", "30"]
CALIBRATE = ["calibrate", str(SHOTS), "--thickness", "3.18", "--pstar", "3", "--alpha", "45"]
# (command line before the flag, the flag, the file's suffix). ARCHIVE: a small archive.
OUTPUT_FLAGS = [
    (["run", *SCENE], "--trajectory", ".csv"),
    (["crater", *SCENE], "--csv", ".csv"),
    (["crater", *SCENE], "--png", ".png"),
    (["sweep", "--preset", "2024-T3/3.18", "--speeds", "300,600", "--obliquities", "30"],
     "--csv", ".csv"),
    ([*CALIBRATE], "--out", ".json"),
    ([*CALIBRATE], "--png", ".png"),
    (["validate", str(SHOTS), "--preset", "2024-T3/3.18"], "--png", ".png"),
    (["v50", str(GONOGO), "--by-obliquity", "--bootstrap", "0"], "--png", ".png"),
    (["plot", "ARCHIVE", "--run", "v"], "--out", ".png"),
    (["compare", "ARCHIVE", "v", "w"], "--png", ".svg"),
    (["map", "--preset", "2024-T3/3.18", "--speeds", "300:900:3", "--obliquities", "0,45",
      "--tolerance", "5"], "--csv", ".csv"),
]  # fmt: skip
IDS = [f"{argv[0]} {flag}" for argv, flag, _ in OUTPUT_FLAGS]


@pytest.fixture(scope="module")
def archive(tmp_path_factory) -> Path:
    path = tmp_path_factory.mktemp("archive") / "a.h5"
    variants = [pi.Variant("v"), pi.Variant("w", integrator="segment")]
    pi.Study.grid("f", ["2024-T3/3.18"], [0], np.array([300.0, 900.0]), variants).run(archive=path)
    return path


def command(argv: list[str], flag: str, target: Path, archive: Path) -> list[str]:
    return [a.replace("ARCHIVE", str(archive)) for a in argv] + [flag, str(target)]


def old_contents(path: Path, mode: int) -> bytes:
    path.write_bytes(b"what was there\n")
    path.chmod(mode)
    return path.read_bytes()


@pytest.mark.parametrize(("argv", "flag", "suffix"), OUTPUT_FLAGS, ids=IDS)
def test_a_full_disk_keeps_the_old_file_at_every_output_flag(
    argv, flag, suffix, tmp_path, monkeypatch, archive
):
    target = tmp_path / f"out{suffix}"
    before = old_contents(target, 0o644)

    def full_disk(stage: str) -> None:
        if stage == "write":
            raise OSError(errno.ENOSPC, os.strerror(errno.ENOSPC))

    monkeypatch.setattr(output, "fault_point", full_disk)
    code, _, err = run_cli(command(argv, flag, target, archive))
    assert_one_line(code, err, flag, "No space left on device")
    assert target.read_bytes() == before
    assert sorted(p.name for p in tmp_path.iterdir()) == [target.name]


@pytest.mark.parametrize(("argv", "flag", "suffix"), OUTPUT_FLAGS, ids=IDS)
def test_every_output_flag_follows_a_symlink_and_keeps_the_mode(
    argv, flag, suffix, tmp_path, archive
):
    real = tmp_path / f"real{suffix}"
    old_contents(real, 0o640)
    link = tmp_path / f"link{suffix}"
    link.symlink_to(real)
    code, _, err = run_cli(command(argv, flag, link, archive))
    assert code == 0, err
    assert link.is_symlink() and os.readlink(link) == str(real)
    assert real.read_bytes() != b"what was there\n" and real.stat().st_size > 0
    assert stat.S_IMODE(real.stat().st_mode) == 0o640


@pytest.mark.parametrize(("argv", "flag", "suffix"), OUTPUT_FLAGS, ids=IDS)
def test_no_output_flag_replaces_a_device(argv, flag, suffix, tmp_path, archive):
    # Before issue 15, `--csv /dev/null` run as root replaced /dev/null by a file. A
    # link gives the device a name with the flag's suffix (a figure's says its format).
    device = tmp_path / f"null{suffix}"
    device.symlink_to("/dev/null")
    code, _, err = run_cli(command(argv, flag, device, archive))
    assert_one_line(code, err, flag, "not a regular file")
    assert stat.S_ISCHR(os.stat("/dev/null").st_mode) and device.is_symlink()


def test_a_read_only_directory_is_one_line_before_any_work(tmp_path):
    locked = tmp_path / "locked"
    locked.mkdir()
    locked.chmod(0o555)
    try:
        if os.access(locked, os.W_OK):
            pytest.skip("this user writes into read-only directories (root)")
        code, _, err = run_cli(["crater", *SCENE, "--csv", str(locked / "c.csv")])
        assert_one_line(code, err, "--csv", "not writable")
        assert list(locked.iterdir()) == []
    finally:
        locked.chmod(0o755)


def test_an_unreadable_archive_is_read_by_root_and_one_line_for_others(tmp_path, archive):
    path = tmp_path / "closed.h5"
    path.write_bytes(archive.read_bytes())
    shutil.copytree(pi.Archive(archive).data, tmp_path / "closed.h5.d")  # its data, renamed
    path.chmod(0o000)
    code, out, err = run_cli(["show", str(path)])
    if os.access(path, os.R_OK):  # root reads any file: the right result is the listing
        assert code == 0 and "f/v" in out, err
    else:
        assert_one_line(code, err, "permission denied")


def test_a_full_disk_during_reproduce_is_one_line_and_keeps_what_was_there(tmp_path, monkeypatch):
    out = tmp_path / "report"
    out.mkdir()
    before = old_contents(out / "report.h5", 0o644)  # not an archive: refused untouched

    code, _, err = run_cli(["reproduce", "--out", str(out)])
    assert_one_line(code, err, "report.h5")
    assert (out / "report.h5").read_bytes() == before
    (out / "report.h5").unlink()

    def full_disk(stage: str) -> None:
        if stage == "write":
            raise OSError(errno.ENOSPC, os.strerror(errno.ENOSPC))

    monkeypatch.setattr(appending, "fault_point", full_disk)
    code, _, err = run_cli(["reproduce", "--out", str(out)])
    assert_one_line(code, err, "No space left on device", "the archive is unchanged")
    assert sorted(p.name for p in out.iterdir() if not p.name.endswith(".lock")) == []
