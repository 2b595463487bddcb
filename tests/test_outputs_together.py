"""Outputs that belong together land together (storage.together): a CSV and its JSON
sidecar (``sweep --csv``, ``run --trajectory``), a plate file and its figure
(``calibrate --out --png``), a section or bands and their figure (``crater``, ``limits``
``--csv --png``). An interrupt between the two renames lands after both; a failure of
the second rename puts the first file back; an interrupt while the files are written
leaves both old files. Faults and signals are injected at the writer's named stages
(storage.output.fault_point), deterministically: the process signals itself."""

from __future__ import annotations

import errno
import hashlib
import json
import os
import signal
import subprocess
import sys
import textwrap
from pathlib import Path

import pytest
from test_output_files import run_cli

from plateimpact.cli.sidecar import pair_matches
from plateimpact.storage import output

SHOTS = Path(__file__).resolve().parents[1] / "studies" / "data" / "shots_2024T3_3.18mm.csv"
SCENE = ["--preset", "2024-T3/3.18", "--speed", "500", "--obliquity", "30"]
SWEEP = ["sweep", "--preset", "2024-T3/3.18", "--speeds", "300,600", "--obliquities", "30"]
CALIBRATE = ["calibrate", str(SHOTS), "--thickness", "3.18", "--pstar", "3", "--alpha", "45"]
LIMITS = ["limits", "--preset", "2024-T3/3.18", "--obliquities", "30", "--tolerance", "5"]
# (command line, the first file's flag and name, the second's, or None: the sidecar)
PAIRS = [
    (SWEEP, ("--csv", "s.csv"), None),
    (["run", *SCENE], ("--trajectory", "t.csv"), None),
    (CALIBRATE, ("--out", "plate.json"), ("--png", "fit.png")),
    (["crater", *SCENE, "--dpi", "50"], ("--csv", "c.csv"), ("--png", "c.png")),
    ([*LIMITS, "--dpi", "50"], ("--csv", "b.csv"), ("--png", "b.png")),
]
IDS = [f"{argv[0]} {first[0]}" for argv, first, _ in PAIRS]


@pytest.fixture(autouse=True)
def python_sigint():
    """SIGINT as Python installs it (KeyboardInterrupt). A shell without job control starts
    a background job (``pytest &``, a CI runner) with SIGINT ignored, and Python keeps an
    ignored SIGINT ignored: the interrupts these tests send would then do nothing."""
    before = signal.signal(signal.SIGINT, signal.default_int_handler)
    yield
    signal.signal(signal.SIGINT, before)


def pair(tmp_path: Path, argv: list[str], first, second) -> tuple[list[str], Path, Path]:
    """The command line writing both files, and the two paths (old contents in place)."""
    one = tmp_path / first[1]
    other = tmp_path / second[1] if second else Path(f"{one}.json")
    command = [*argv, first[0], str(one)] + ([second[0], str(other)] if second else [])
    for path in (one, other):
        path.write_bytes(b"what was there\n")
    return command, one, other


def stage_counter(at: str, number: int, act):
    """A fault point that calls ``act()`` at the ``number``-th stage ``at``."""
    seen = {"count": 0}

    def fault(stage: str) -> None:
        if stage == at:
            seen["count"] += 1
            if seen["count"] == number:
                act()

    return fault


def interrupt() -> None:
    os.kill(os.getpid(), signal.SIGINT)


def leftovers(directory: Path) -> list[str]:
    return sorted(p.name for p in directory.iterdir() if p.name.endswith(".tmp"))


@pytest.mark.parametrize(("argv", "first", "second"), PAIRS, ids=IDS)
def test_an_interrupt_between_the_two_renames_lands_after_both(
    tmp_path, monkeypatch, argv, first, second
):
    command, one, other = pair(tmp_path, argv, first, second)
    monkeypatch.setattr(output, "fault_point", stage_counter("replace", 2, interrupt))
    code, _, err = run_cli(command)
    assert code == 130 and err == "plateimpact: interrupted\n", err
    for path in (one, other):  # both new
        assert path.read_bytes() != b"what was there\n", path
    if second is None:
        assert pair_matches(one)
    assert leftovers(tmp_path) == []


@pytest.mark.parametrize(("argv", "first", "second"), PAIRS, ids=IDS)
def test_an_interrupt_while_the_files_are_written_leaves_both_old(
    tmp_path, monkeypatch, argv, first, second
):
    command, one, other = pair(tmp_path, argv, first, second)
    monkeypatch.setattr(output, "fault_point", stage_counter("fsync", 2, interrupt))
    code, _, err = run_cli(command)
    assert code == 130 and err == "plateimpact: interrupted\n", err
    for path in (one, other):
        assert path.read_bytes() == b"what was there\n", path
    assert leftovers(tmp_path) == []


@pytest.mark.parametrize(("argv", "first", "second"), PAIRS, ids=IDS)
def test_a_failed_second_rename_puts_the_first_file_back(
    tmp_path, monkeypatch, argv, first, second
):
    command, one, other = pair(tmp_path, argv, first, second)

    def fail() -> None:
        raise OSError(errno.EIO, os.strerror(errno.EIO))

    monkeypatch.setattr(output, "fault_point", stage_counter("replace", 2, fail))
    code, _, err = run_cli(command)
    assert code == 2 and err.count("\n") == 1 and "Input/output error" in err, err
    for path in (one, other):
        assert path.read_bytes() == b"what was there\n", path
    assert leftovers(tmp_path) == []


def test_a_first_file_that_is_new_is_removed_again_when_the_second_rename_fails(
    tmp_path, monkeypatch
):
    target = tmp_path / "s.csv"

    def fail() -> None:
        raise OSError(errno.EIO, os.strerror(errno.EIO))

    monkeypatch.setattr(output, "fault_point", stage_counter("replace", 2, fail))
    code, _, err = run_cli([*SWEEP, "--csv", str(target)])
    assert code == 2 and sorted(p.name for p in tmp_path.iterdir()) == []


def test_a_sigterm_between_the_two_renames_ends_the_process_after_both(tmp_path):
    target = tmp_path / "s.csv"
    for path in (target, Path(f"{target}.json")):
        path.write_bytes(b"what was there\n")
    script = textwrap.dedent(
        f"""
        import os, signal, sys
        from plateimpact.cli import main
        from plateimpact.storage import output
        seen = []
        def fault(stage):
            if stage == "replace":
                seen.append(stage)
                if len(seen) == 2:
                    os.kill(os.getpid(), signal.SIGTERM)
        output.fault_point = fault
        sys.exit(main({[*SWEEP, "--csv", str(target)]!r}))
        """
    )
    done = subprocess.run([sys.executable, "-c", script], capture_output=True)
    assert done.returncode == -signal.SIGTERM, done.stderr
    assert pair_matches(target) and leftovers(tmp_path) == []


@pytest.mark.parametrize("command", [SWEEP, ["run", *SCENE]], ids=["sweep", "run"])
def test_the_sidecar_records_the_sha256_of_its_csv(tmp_path, command):
    target = tmp_path / "out.csv"
    flag = "--csv" if command[0] == "sweep" else "--trajectory"
    code, _, err = run_cli([*command, flag, str(target)])
    assert code == 0, err
    record = json.loads(Path(f"{target}.json").read_text())
    assert record["csv_sha256"] == hashlib.sha256(target.read_bytes()).hexdigest()
    target.write_bytes(target.read_bytes() + b"\n")  # a CSV from another run
    assert not pair_matches(target)


def test_a_trajectorys_sidecar_reruns_the_scene(tmp_path):
    target = tmp_path / "t.csv"
    code, out, _ = run_cli(["run", *SCENE, "--trajectory", str(target), "--json"])
    assert code == 0
    code, again, err = run_cli(["run", "--inputs", f"{target}.json", "--json"])
    assert code == 0, err
    first, second = json.loads(out), json.loads(again)
    assert second["exit_speed_m_s"] == first["exit_speed_m_s"]
    assert second["inputs"]["plate"] == first["inputs"]["plate"]
