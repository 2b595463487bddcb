"""Output files (CSV, figures, plate files, trajectories): checked before any work, written
all or nothing, never replacing what is not a regular file, keeping the target's mode;
failures injected deterministically at each stage of a write (storage.output)."""

from __future__ import annotations

import contextlib
import errno
import io
import os
import stat
import subprocess
import sys
from pathlib import Path

import pytest

from plateimpact.cli import main
from plateimpact.storage import output

SWEEP = ["sweep", "--preset", "2024-T3/3.18", "--speeds", "300,600", "--obliquities", "30"]
STAGES = ("open", "write", "fsync", "chmod", "replace")


def run_cli(argv: list[str]) -> tuple[int, str, str]:
    out, err = io.StringIO(), io.StringIO()
    with contextlib.redirect_stdout(out), contextlib.redirect_stderr(err):
        try:
            code = main(argv)
        except SystemExit as exc:  # argparse's own errors
            code = int(exc.code or 0)
        except KeyboardInterrupt:  # an interrupt that escaped the command: a failure
            code = -1
    return code, out.getvalue(), err.getvalue()


def assert_one_line(code: int, err: str, *named: str) -> None:
    assert code == 2, err
    assert err.count("\n") == 1 and err.startswith("plateimpact: error: "), err
    assert "Traceback" not in err
    for word in named:
        assert word in err, (word, err)


def old_file(path: Path, mode: int = 0o644) -> bytes:
    path.write_bytes(b"what was there\n")
    path.chmod(mode)
    return path.read_bytes()


def leftovers(directory: Path) -> list[str]:
    return sorted(p.name for p in directory.iterdir() if p.name.endswith(".tmp"))


@pytest.mark.parametrize("stage", STAGES)
def test_a_failure_at_any_stage_keeps_the_old_file_and_leaves_no_debris(
    tmp_path, stage, monkeypatch
):
    target = tmp_path / "sweep.csv"
    before = old_file(target)

    def full_disk(where: str) -> None:
        if where == stage:
            raise OSError(errno.ENOSPC, os.strerror(errno.ENOSPC))

    monkeypatch.setattr(output, "fault_point", full_disk)
    code, _, err = run_cli([*SWEEP, "--csv", str(target)])
    assert_one_line(code, err, "--csv", "No space left on device")
    assert target.read_bytes() == before and stat.S_IMODE(target.stat().st_mode) == 0o644
    assert leftovers(tmp_path) == []


KILLED_WRITER = """
import os, signal, sys
from plateimpact.storage import output
def die(stage):
    if stage == sys.argv[2]:
        os.kill(os.getpid(), signal.SIGKILL)
output.fault_point = die
output.write_text(sys.argv[1], "new contents\\n", "--csv")
"""


@pytest.mark.parametrize("stage", STAGES)
def test_a_writer_killed_at_any_stage_leaves_the_old_file_and_the_next_cleans_up(tmp_path, stage):
    target = tmp_path / "out.csv"
    before = old_file(target)
    done = subprocess.run([sys.executable, "-c", KILLED_WRITER, str(target), stage])
    assert done.returncode == -9
    assert target.read_bytes() == before
    output.write_text(target, "next\n", "--csv")  # the next writer
    assert target.read_text() == "next\n" and leftovers(tmp_path) == []


def test_a_symlink_is_followed_and_the_targets_mode_kept(tmp_path):
    real = tmp_path / "real.csv"
    old_file(real, 0o640)
    link = tmp_path / "link.csv"
    link.symlink_to(real)
    code, _, err = run_cli([*SWEEP, "--csv", str(link)])
    assert code == 0, err
    assert link.is_symlink() and os.readlink(link) == str(real)
    assert real.read_text().startswith("preset,") and stat.S_IMODE(real.stat().st_mode) == 0o640


def test_a_new_file_gets_the_umasks_mode_not_0600(tmp_path):
    target = tmp_path / "new.csv"
    assert run_cli([*SWEEP, "--csv", str(target)])[0] == 0
    assert stat.S_IMODE(target.stat().st_mode) == 0o666 & ~output.umask()


def test_what_is_not_a_regular_file_is_never_replaced(tmp_path):
    fifo = tmp_path / "pipe.csv"
    os.mkfifo(fifo)
    code, _, err = run_cli([*SWEEP, "--csv", str(fifo)])
    assert_one_line(code, err, "--csv", "not a regular file")
    assert stat.S_ISFIFO(fifo.stat().st_mode)
    dangling_dir = tmp_path / "dir.png"
    dangling_dir.mkdir()
    link = tmp_path / "link.png"
    link.symlink_to(dangling_dir)
    code, _, err = run_cli(["crater", "--preset", "6061-T6/9.53", "--speed", "263",
                            "--obliquity", "60", "--png", str(link)])  # fmt: skip
    assert_one_line(code, err, "--png", "is a directory")
    assert dangling_dir.is_dir() and link.is_symlink()


def test_a_read_only_target_is_refused(tmp_path):
    target = tmp_path / "kept.csv"
    before = old_file(target, 0o444)
    code, _, err = run_cli([*SWEEP, "--csv", str(target)])
    assert_one_line(code, err, "--csv", "read-only")
    assert target.read_bytes() == before


@pytest.mark.parametrize(
    ("name", "words"),
    [
        ("", ["--csv", "give a file name"]),
        (".", ["--csv", "is a directory"]),
        ("/", ["--csv", "is a directory"]),
        ("DIR/", ["--csv", "is a directory"]),
        ("missing/out.csv", ["--csv", "does not exist"]),
        ("x" * 300 + ".csv", ["--csv", "longer than"]),
    ],
)
def test_impossible_output_names_are_refused_before_any_work(tmp_path, monkeypatch, name, words):
    monkeypatch.chdir(tmp_path)
    (tmp_path / "DIR").mkdir()
    code, out, err = run_cli([*SWEEP, "--csv", name])
    assert_one_line(code, err, *words)
    assert out == "" and sorted(p.name for p in tmp_path.iterdir()) == ["DIR"]


@pytest.mark.parametrize(
    "argv",
    [
        ["plot", "ARCHIVE", "--run", "v", "--out", "OUT/x.unknownext"],
        ["compare", "ARCHIVE", "v", "v", "--png", "OUT/x.txt"],
        ["crater", "--preset", "6061-T6/9.53", "--speed", "263", "--obliquity", "60",
         "--png", "OUT/x.doc"],
    ],
)  # fmt: skip
def test_a_figure_name_must_say_its_format(tmp_path, argv):
    import numpy as np

    import plateimpact as pi

    archive = tmp_path / "a.h5"
    pi.Study.grid("f", ["2024-T3/3.18"], [0], np.array([300.0, 900.0]), pi.Variant("v")).run(
        archive=archive
    )
    argv = [a.replace("ARCHIVE", str(archive)).replace("OUT", str(tmp_path)) for a in argv]
    code, _, err = run_cli(argv)
    assert_one_line(code, err, "end the name with one of .png")
    assert not [p for p in tmp_path.iterdir() if p.name.startswith("x.")]


@contextlib.contextmanager
def mounted(tmp_path: Path, options: str):
    """A small tmpfs at tmp_path/mnt (root only; skipped where it cannot be mounted)."""
    point = tmp_path / "mnt"
    point.mkdir()
    if os.geteuid() != 0:
        pytest.skip("mounting a small filesystem needs root")
    done = subprocess.run(["mount", "-t", "tmpfs", "-o", options, "tmpfs", str(point)],
                          capture_output=True)  # fmt: skip
    if done.returncode != 0:
        pytest.skip(f"cannot mount a tmpfs here: {done.stderr.decode().strip()}")
    try:
        yield point
    finally:
        subprocess.run(["umount", str(point)], check=True)


def test_a_full_disk_keeps_the_old_file_and_says_so_in_one_line(tmp_path):
    with mounted(tmp_path, "size=64k") as disk:
        target = disk / "sweep.csv"
        before = old_file(target)
        (disk / "filler").write_bytes(b"\0" * (64 * 1024 - 2 * len(before) - 4096))
        argv = ["sweep", "--preset", "2024-T3/3.18", "--speeds", "100:1500:400",
                "--obliquities", "0,30,60", "--csv", str(target)]  # fmt: skip
        code, _, err = run_cli(argv)
        assert_one_line(code, err, "--csv", "No space left on device")
        assert target.read_bytes() == before and leftovers(disk) == []


def test_a_read_only_filesystem_is_one_line(tmp_path):
    with mounted(tmp_path, "size=64k,ro") as disk:
        code, _, err = run_cli([*SWEEP, "--csv", str(disk / "out.csv")])
        assert_one_line(code, err, "--csv")


def test_a_full_standard_output_is_one_line(tmp_path):
    script = f"import sys\nfrom plateimpact.cli import main\nsys.exit(main({SWEEP!r}))\n"
    with open("/dev/full", "w") as full:
        done = subprocess.run([sys.executable, "-c", script], stdout=full, stderr=subprocess.PIPE)
    assert done.returncode == 2
    assert done.stderr.decode().count("\n") == 1 and b"standard output" in done.stderr
