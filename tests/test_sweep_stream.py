"""Sweeps at scale: the grid run and written a chunk at a time (the same bytes whatever the
chunk size), atomically even when streamed, refused past the limit unless --force, and
a progress bar on a terminal only for long runs."""

from __future__ import annotations

import contextlib
import csv
import errno
import io
import os
import sys

import numpy as np
import pytest
import tqdm.std
from test_progress import Pipe, Terminal, ticking

import plateimpact as pi
from plateimpact import presets
from plateimpact.cli import SWEEP_COLUMNS, main, sweep_csv
from plateimpact.cli.commands import sweep as scene_commands
from plateimpact.storage import output

PLATE = "2024-T3/3.18"
SPEEDS, OBLIQUITIES = "100:1400:7", "0,30,60"  # 21 scenes, every outcome
SWEEP = ["sweep", "--preset", PLATE, "--speeds", SPEEDS, "--obliquities", OBLIQUITIES]


def run_cli(argv: list[str]) -> tuple[int, str, str]:
    out, err = io.StringIO(), io.StringIO()
    with contextlib.redirect_stdout(out), contextlib.redirect_stderr(err):
        code = main(argv)
    return code, out.getvalue(), err.getvalue()


def one_batch_csv() -> str:
    """The oracle: the whole grid as one batch, each row written by the csv module."""
    speeds, obliquities = np.linspace(100.0, 1400.0, 7), np.array([0.0, 30.0, 60.0])
    batch = pi.SceneBatch.grid(
        presets.DEFAULT_SPHERE, presets.plate(PLATE), speeds, np.radians(obliquities)
    )
    result = pi.Simulation.from_names().run_batch(batch)
    buffer = io.StringIO()
    writer = csv.writer(buffer, lineterminator="\n")
    writer.writerow(SWEEP_COLUMNS)
    for i in range(len(result)):
        writer.writerow(
            [
                PLATE,
                repr(float(speeds[i % 7])),
                repr(float(obliquities[i // 7])),
                pi.Outcome(int(result.outcome[i])).label,
                repr(float(result.exit_speed[i])),
                repr(float(result.exit_obliquity[i]) / (np.pi / 180.0)),
                repr(float(result.contact_time[i])),
                repr(float(result.max_penetration[i]) / 1e-3),
                "true" if result.plate_failed[i] else "false",
            ]
        )
    return buffer.getvalue()


@pytest.fixture(scope="module")
def expected() -> str:
    return one_batch_csv()


def test_the_oracle_has_every_outcome(expected):
    outcomes = {row["outcome"] for row in csv.DictReader(io.StringIO(expected))}
    assert outcomes == {"ricochet", "embedment", "perforation"}


# chunks of one scene, across rows of the grid (7 per obliquity), a divisor of the
# grid, the whole grid, more than the grid
@pytest.mark.parametrize("chunk_size", [1, 4, 7, 21, 1000])
def test_streamed_csv_is_the_one_batch_csv_whatever_the_chunk(
    chunk_size, expected, monkeypatch, tmp_path
):
    monkeypatch.setattr(sweep_csv, "SWEEP_CHUNK_SIZE", chunk_size)
    code, out, _ = run_cli(SWEEP)
    assert code == 0 and out == expected
    target = tmp_path / "sweep.csv"
    code, out, _ = run_cli([*SWEEP, "--csv", str(target)])
    assert code == 0 and target.read_text() == expected
    counts = {o: sum(f",{o}," in line for line in expected.splitlines()) for o in
              ("ricochet", "embedment", "perforation")}  # fmt: skip
    assert out.splitlines()[0] == f"wrote 21 scenes to {target}: " + ", ".join(
        f"{n} {o}" for o, n in counts.items()
    )
    assert out.splitlines()[1] == f"inputs and provenance: {target}.json"  # the sidecar


@pytest.mark.parametrize(("speeds", "obliquities", "chunk"), [(7, 3, 4), (1, 5, 2), (5, 1, 5)])
def test_grid_chunks_are_the_grid_in_order(speeds, obliquities, chunk):
    sphere, plate = presets.DEFAULT_SPHERE, presets.plate(PLATE)
    v, theta = np.linspace(100.0, 900.0, speeds), np.linspace(0.0, 1.2, obliquities)
    chunks = list(pi.SceneBatch.grid_chunks(sphere, plate, v, theta, chunk))
    assert [c.size for c in chunks[:-1]] == [chunk] * (len(chunks) - 1)
    assert 1 <= chunks[-1].size <= chunk
    whole = pi.SceneBatch.grid(sphere, plate, v, theta)
    joined = pi.SceneBatch.concat(chunks)
    assert joined.columns.keys() == whole.columns.keys()
    for name, column in whole.columns.items():
        assert np.array_equal(joined.columns[name], column), name


def test_grid_chunks_are_checked_before_the_first_chunk():
    sphere, plate = presets.DEFAULT_SPHERE, presets.plate(PLATE)
    with pytest.raises(pi.ParameterError, match="impact_speed"):
        pi.SceneBatch.grid_chunks(sphere, plate, [100.0, -1.0], [0.0], 10)
    with pytest.raises(pi.ParameterError, match="chunk_size"):
        pi.SceneBatch.grid_chunks(sphere, plate, [100.0], [0.0], 0)


@pytest.mark.parametrize("label", ["plain", "with,comma", 'with "quotes"', "new\nline"])
def test_a_label_is_quoted_as_the_csv_module_quotes_it(label):
    row = f"{sweep_csv.csv_field(label)},1.0\n"
    assert next(csv.reader(io.StringIO(row))) == [label, "1.0"]


def full_disk_at_chunk(monkeypatch, failing: int) -> list[int]:
    """Make the ``failing``-th chunk of a streamed file fail as on a full disk."""
    written = [0]

    def fault(stage: str) -> None:
        if stage == "chunk":
            written[0] += 1
            if written[0] == failing:
                raise OSError(errno.ENOSPC, os.strerror(errno.ENOSPC))

    monkeypatch.setattr(output, "fault_point", fault)
    return written


def test_a_full_disk_mid_stream_keeps_the_old_file(monkeypatch, tmp_path):
    monkeypatch.setattr(sweep_csv, "SWEEP_CHUNK_SIZE", 4)  # header + 6 chunks
    target = tmp_path / "sweep.csv"
    target.write_bytes(b"what was there\n")
    written = full_disk_at_chunk(monkeypatch, failing=3)  # after the header and a chunk
    code, out, err = run_cli([*SWEEP, "--csv", str(target)])
    assert code == 2 and out == ""
    assert err.count("\n") == 1 and err.startswith("plateimpact: error: --csv: ")
    assert "No space left on device" in err
    assert written == [3]  # it failed midway and stopped there
    assert target.read_bytes() == b"what was there\n"
    assert sorted(os.listdir(tmp_path)) == ["sweep.csv"]  # no temporary left


def test_a_failing_scene_mid_stream_keeps_the_old_file(monkeypatch, tmp_path):
    monkeypatch.setattr(sweep_csv, "SWEEP_CHUNK_SIZE", 4)
    target = tmp_path / "sweep.csv"
    target.write_bytes(b"what was there\n")
    run_batch, calls = pi.Simulation.run_batch, [0]

    def fails_second(self, batch, **kwargs):
        calls[0] += 1
        if calls[0] == 2:
            raise pi.IntegrationError("dopri5: 1 scene(s) unfinished (injected)")
        return run_batch(self, batch, **kwargs)

    monkeypatch.setattr(pi.Simulation, "run_batch", fails_second)
    code, _, err = run_cli([*SWEEP, "--csv", str(target)])
    assert code == 2 and err.count("\n") == 1 and "injected" in err
    assert target.read_bytes() == b"what was there\n"
    assert sorted(os.listdir(tmp_path)) == ["sweep.csv"]


def test_more_than_the_limit_needs_force(monkeypatch, tmp_path, expected):
    monkeypatch.setattr(scene_commands, "MAX_SWEEP_SCENES", 20)  # the grid has 21
    target = tmp_path / "sweep.csv"
    code, out, err = run_cli([*SWEEP, "--csv", str(target)])
    assert code == 2 and out == "" and not target.exists()
    assert err.count("\n") == 1 and err.startswith("plateimpact: error: --speeds, --obliquities:")
    assert "7 x 3 = 21 scenes" in err and "20" in err and "--force" in err
    code, _, _ = run_cli([*SWEEP, "--csv", str(target), "--force"])
    assert code == 0 and target.read_text() == expected
    monkeypatch.setattr(scene_commands, "MAX_SWEEP_SCENES", 21)  # at the limit: no --force
    assert run_cli(SWEEP)[0] == 0


def test_the_help_states_the_limit(capsys):
    with pytest.raises(SystemExit):
        main(["sweep", "--help"])
    assert "more than 1,000,000 scenes" in " ".join(capsys.readouterr().out.split())


@pytest.mark.parametrize(
    ("stderr", "seconds_per_call", "shown"),
    [
        (Terminal, 1.0, True),  # a long run on a terminal
        (Terminal, 0.0, False),  # a short one: under the delay
        (Pipe, 1.0, False),  # a long one into a pipe or file
    ],
)
def test_a_progress_bar_on_a_terminal_for_long_runs_only(
    stderr, seconds_per_call, shown, monkeypatch
):
    monkeypatch.setattr(sweep_csv, "SWEEP_CHUNK_SIZE", 4)
    monkeypatch.setattr(tqdm.std, "time", ticking(seconds_per_call))
    out, err = io.StringIO(), stderr()
    monkeypatch.setattr(sys, "stderr", err)
    with contextlib.redirect_stdout(out):
        assert main(SWEEP) == 0
    assert out.getvalue() == one_batch_csv()  # never on standard output
    if shown:
        assert "sweep:" in err.getvalue() and "21/21" in err.getvalue()
    else:
        assert err.getvalue() == ""
