"""Impossible output paths are one line naming the flag the user typed, before any work:
a name longer than the filesystem takes (300 bytes), a path longer than PATH_MAX (5,000
bytes), a file where a directory must be, a missing directory, a read-only filesystem
(storage.output.check_path, cli.common.output_directory). ``reproduce --out`` creates its
directory only after the same checks, keeping room in the path for what goes inside."""

from __future__ import annotations

import os
from pathlib import Path

import pytest
from test_output_files import assert_one_line, mounted, run_cli
from test_output_flags import IDS, OUTPUT_FLAGS, command

import plateimpact as pi

LONG_NAME = "n" * 300


@pytest.fixture(scope="module")
def archive(tmp_path_factory) -> Path:
    """A small archive for plot and compare (runs v and w)."""
    path = tmp_path_factory.mktemp("archive") / "a.h5"
    variants = [pi.Variant("v"), pi.Variant("w", integrator="segment")]
    pi.Study.grid("f", ["2024-T3/3.18"], [0], [300.0, 900.0], variants).run(archive=path)
    return path


def bad_paths(tmp_path: Path, suffix: str) -> dict[str, tuple[Path, str]]:
    """Each impossible path, with a word its message must hold."""
    (tmp_path / "a-file").write_text("not a directory\n")
    return {
        "name of 300 bytes": (tmp_path / f"{LONG_NAME}{suffix}", "longer than 255 bytes"),
        "directory name of 300 bytes": (tmp_path / LONG_NAME / f"x{suffix}", "longer than"),
        "path of 5,000 bytes": (tmp_path.joinpath(*["ab"] * 1700) / f"x{suffix}", "PATH_MAX"),
        "a file as directory": (tmp_path / "a-file" / f"x{suffix}", "is not a directory"),
        "a file deeper": (tmp_path / "a-file" / "y" / f"x{suffix}", "is not a directory"),
        "a missing directory": (tmp_path / "missing" / f"x{suffix}", "does not exist"),
    }


@pytest.mark.parametrize(("argv", "flag", "suffix"), OUTPUT_FLAGS, ids=IDS)
def test_impossible_output_paths_are_one_line_naming_the_flag(
    argv, flag, suffix, tmp_path, archive
):
    for what, (target, words) in bad_paths(tmp_path, suffix).items():
        code, out, err = run_cli(command(argv, flag, target, archive))
        assert_one_line(code, err, flag, words)
        assert len(err) < 600, (what, err)  # the path in it cut short
        assert out == "", what
    assert sorted(p.name for p in tmp_path.iterdir()) == ["a-file"]  # nothing written


def test_impossible_reproduce_directories_are_one_line_before_any_work(tmp_path):
    (tmp_path / "a-file").write_text("not a directory\n")
    for out, words in [
        (tmp_path / LONG_NAME, "NAME_MAX (255)"),
        (tmp_path.joinpath(*["ab"] * 2500), "PATH_MAX"),
        # short enough itself, too long for the archive's data files inside
        (tmp_path.joinpath(*["ab"] * ((4000 - len(str(tmp_path))) // 3)), "PATH_MAX"),
        (tmp_path / "a-file", "exists and is not a directory"),
        (tmp_path / "a-file" / "report", "is not a directory"),
        (tmp_path / "missing" / "report", "does not exist"),
    ]:
        code, printed, err = run_cli(["reproduce", "--quick", "--out", str(out)])
        assert_one_line(code, err, "--out", words)
        assert printed == "" and len(err) < 600
    assert sorted(p.name for p in tmp_path.iterdir()) == ["a-file"]


def test_reproduce_on_a_read_only_filesystem_is_one_line(tmp_path):
    with mounted(tmp_path, "size=64k,ro") as disk:
        code, _, err = run_cli(["reproduce", "--quick", "--out", str(disk / "report")])
        assert_one_line(code, err, "--out", "read-only filesystem")
        code, _, err = run_cli(["sweep", "--preset", "2024-T3/3.18", "--speeds", "300",
                                "--obliquities", "0", "--csv", str(disk / "s.csv")])  # fmt: skip
        assert_one_line(code, err, "--csv", "read-only filesystem")
        assert os.listdir(disk) == []
