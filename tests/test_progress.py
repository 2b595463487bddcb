"""Progress on a terminal for long work: a bar on standard error once the work has lasted
2 s (a fake clock makes it last), never off a terminal or on standard output."""

from __future__ import annotations

import contextlib
import io
import json
import sys
from pathlib import Path

import tqdm.std

import plateimpact as pi
from plateimpact.cli import main

PLATE = "2024-T3/3.18"


class Terminal(io.StringIO):
    def isatty(self) -> bool:
        return True


class Pipe(io.StringIO):
    def isatty(self) -> bool:
        return False


def ticking(seconds_per_call: float):
    """A clock for tqdm that advances ``seconds_per_call`` each time it is read."""
    now = [1000.0]

    def clock() -> float:
        now[0] += seconds_per_call
        return now[0]

    return clock


def test_limits_reports_its_passes_on_a_terminal(monkeypatch):
    monkeypatch.setattr(tqdm.std, "time", ticking(1.0))
    err = Terminal()
    monkeypatch.setattr(sys, "stderr", err)
    argv = ["limits", "--preset", PLATE, "--obliquities", "45", "--resolution", "50",
            "--tolerance", "1"]  # fmt: skip
    with contextlib.redirect_stdout(io.StringIO()) as out:
        assert main(argv) == 0
    scenes = int(out.getvalue().split(" scenes in ")[0].rsplit(" ", 1)[-1].replace(",", ""))
    assert f"limits: {scenes}" in err.getvalue().replace(",", "")  # every scene counted


def test_plot_reports_its_stages_on_a_terminal(monkeypatch, tmp_path):
    archive = tmp_path / "a.h5"
    pi.Study.grid("s", [PLATE], [0, 60], [300.0, 900.0], pi.Variant("plugging")).run(
        archive=archive
    )
    monkeypatch.setattr(tqdm.std, "time", ticking(1.0))
    err = Terminal()
    monkeypatch.setattr(sys, "stderr", err)
    argv = ["plot", str(archive), "--run", "plugging", "--out", str(tmp_path / "p.png")]
    with contextlib.redirect_stdout(io.StringIO()) as out:
        assert main(argv) == 0
    assert out.getvalue() == f"figure: {tmp_path / 'p.png'}\n"
    assert "plot: 100%" in err.getvalue() and "3/3" in err.getvalue()


def test_calibrate_counts_its_scenes_on_standard_error_only(monkeypatch):
    shots = Path(__file__).resolve().parents[1] / "studies" / "data" / "shots_2024T3_3.18mm.csv"
    monkeypatch.setattr(tqdm.std, "time", ticking(1.0))
    err = Terminal()
    monkeypatch.setattr(sys, "stderr", err)
    argv = ["calibrate", str(shots), "--thickness", "3.18", "--pstar", "3", "--alpha", "45"]
    with contextlib.redirect_stdout(io.StringIO()) as out:
        assert main([*argv, "--json"]) == 0
    assert json.loads(out.getvalue())["newton"]["converged"]  # stdout: the JSON alone
    counted = err.getvalue().rsplit("calibrate: ", 1)[-1].split("scene")[0]
    assert int(counted) > 15  # many model runs at the 15 shots' speeds
