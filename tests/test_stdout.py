"""Standard output that cannot take what a command prints: a full device (``> /dev/full``,
with Python's output buffered or not) or closed (``>&-``). Every command prints one line,
``plateimpact: error: standard output ...``, and exits with code 2: never an internal
error, a traceback, or Python's "Exception ignored" at exit (code 120).

Each case runs in a child forked from one interpreter that has imported plateimpact
(a subprocess per case would spend most of its time importing); the child sets up its
standard output, then exits through ``sys.exit(main(...))`` as the ``plateimpact`` script
does, so that the interpreter's own flush at exit is part of what is checked."""

from __future__ import annotations

import json
import shutil
import subprocess
import sys
import textwrap
from pathlib import Path

from plateimpact.cli.commands import COMMANDS

SHOTS = Path(__file__).resolve().parents[1] / "studies" / "data"
FORMAT1 = Path(__file__).parent / "data" / "format1.h5"

#: The child: fd 1 -> /dev/full (buffered or line by line) or closed, then main.
DRIVER = textwrap.dedent(
    """
    import gc, io, json, os, sys
    from plateimpact.cli import build_parser, main

    def run(cases):
        found = []
        for argv, mode in cases:
            read, write = os.pipe()
            pid = os.fork()
            if pid == 0:
                os.close(read)
                os.dup2(write, 2)
                sys.stderr = io.TextIOWrapper(open(2, "wb", closefd=False), write_through=True)
                if mode == "closed":
                    os.close(1)
                    sys.stdout = None
                else:
                    full = os.open("/dev/full", os.O_WRONLY)
                    os.dup2(full, 1)
                    if mode == "unbuffered":  # as python -u or PYTHONUNBUFFERED=1 make it
                        raw = open(1, "wb", buffering=0, closefd=False)
                        sys.stdout = io.TextIOWrapper(raw, write_through=True)
                    else:  # a file: block-buffered, flushed at exit
                        sys.stdout = open(1, "w", closefd=False)
                sys.exit(main(argv))  # as the console script: the interpreter exits here
            os.close(write)
            with os.fdopen(read, "rb") as pipe:
                err = pipe.read().decode(errors="replace")
            _, status = os.waitpid(pid, 0)
            found.append([argv, mode, os.waitstatus_to_exitcode(status), err])
        return found

    bare, light, heavy = json.loads(sys.argv[1])
    # What is imported stays out of the collector's reach: a child then exits in a
    # tenth of the time (Python's finalisation otherwise walks, and copies, every page
    # of the parent's heap) and still flushes the standard output it sets up below.
    gc.freeze()
    # Its finalisation still touches (and so copies) each page of the heap it inherits:
    # the cases that need less run first, from a smaller heap. First those that need
    # nothing past the entry point (as `plateimpact --version` imports nothing more),
    found = run(bare)
    # then those that need every command's parser and the plug-ins,
    build_parser()
    gc.freeze()
    found += run(light)
    # then the rest: what the commands import when they need it, imported once here
    import plateimpact.storage.export, plateimpact.figures.saving
    import plateimpact.figures.limits_and_maps, plateimpact.figures.validation_panels
    import plateimpact.figures.v50_fits
    # the compiled programs loaded once, here: each child inherits them rather than
    # importing numba and loading a program from the cache again
    from plateimpact.registry.plugin_registry import default_registry
    from plateimpact.solve.compiled.warming import compile_pairs, compiled_pairs
    compile_pairs(compiled_pairs(default_registry()))
    gc.freeze()
    found += run(heavy)
    print(json.dumps(found))
    """
)


Cases = list[tuple[list[str], str]]


def run_cases(bare: Cases, light: Cases, heavy: Cases) -> list[tuple[list[str], str, int, str]]:
    """Each case's (argv, mode, exit code, standard error): ``bare``, cases that import
    nothing past the entry point, run first; then ``light``, those that need no more than
    the commands' parsers and the plug-ins; then ``heavy``, the rest."""
    cases = json.dumps([bare, light, heavy])
    done = subprocess.run([sys.executable, "-c", DRIVER, cases], capture_output=True, text=True)
    assert done.returncode == 0, done.stderr
    return [tuple(case) for case in json.loads(done.stdout)]


def commands(archive: Path, tmp: Path) -> list[list[str]]:
    """Every command that prints, on small inputs."""
    preset = ["--preset", "2024-T3/3.18"]
    few_shots = tmp / "shots.csv"  # validate's work is the shots': a few are enough
    few_shots.write_text(
        "impact_speed_m_s,impact_obliquity_deg,perforated\n300,45,0\n400,45,0\n600,45,1\n"
    )
    scene = [*preset, "--speed", "500", "--obliquity", "45"]
    old = tmp / "format1.h5"  # upgrade's: rewritten by the first case, refused by the rest
    shutil.copy(FORMAT1, old)
    # reproduce's: the session's quick report resumed, so that the command prints its
    # whole report after drawing its figures again, without running its studies again
    report = shutil.copytree(archive.parent, tmp / "r")
    spec = tmp / "spec.json"
    spec.write_text(
        '{"preset": "2024-T3/3.18", "at": {"speed_m_s": 400, "obliquity_deg": 0}, '
        '"inputs": {"speed_m_s": {"normal": {"mean": 400, "sd": 15}}}, "samples": 50}'
    )
    return [
        ["--version"],
        ["--help"],
        ["run", "--help"],
        ["presets"],
        ["presets", "--json"],
        ["plugins"],
        ["plugins", "--details"],
        ["run", *scene],
        ["run", *scene, "--json"],
        ["crater", *scene],
        ["sweep", *preset, "--speeds", "300,600", "--obliquities", "30"],
        ["sweep", *preset, "--speeds", "300,600", "--obliquities", "30", "--csv",
         str(tmp / "s.csv")],
        ["limits", *preset, "--obliquities", "45", "--tolerance", "5"],
        ["map", *preset, "--speeds", "300:900:3", "--obliquities", "0,45", "--tolerance", "5",
         "--png", str(tmp / "m.png"), "--dpi", "50"],
        ["calibrate", str(SHOTS / "shots_2024T3_3.18mm.csv"), *preset],
        ["validate", str(few_shots), "--preset", "SAE1010/1.47"],
        ["v50", str(SHOTS / "gonogo_SAE1010_1.47mm.csv"), "--by-obliquity", "--bootstrap", "0"],
        ["show", str(archive)],
        ["compare", str(archive), "2024-T3_3.18mm/plugging", "2024-T3_3.18mm/large-pstar"],
        ["compare", str(archive), "limits/map_2024-T3_3.18", "limits/map_2024-T3_6.35"],
        ["export", str(archive), "--run", "2024-T3_1.27mm/plugging", "--to", str(tmp / "e.csv")],
        ["plot", str(archive), "--run", "2024-T3_3.18mm/plugging", "--out", str(tmp / "p.png"),
         "--dpi", "50"],
        ["upgrade", str(old)],
        ["reproduce", "--quick", "--resume", "--out", str(report), "--dpi", "50"],
        ["compile"],
        ["uncertainty", str(spec)],
    ]  # fmt: skip


def test_every_command_on_a_full_or_closed_standard_output_is_one_line(quick_report, tmp_path):
    every = commands(quick_report / "report.h5", tmp_path)
    # every command of the table is among them (a new command must be added here)
    assert {argv[0] for argv in every if not argv[0].startswith("-")} == {c.name for c in COMMANDS}
    cheap = [argv for argv in every if argv[0] in ("--version", "--help", "presets", "plugins")]
    both = ("buffered", "unbuffered")
    bare = [(argv, mode) for argv in cheap if argv[0].startswith("-") for mode in both]
    light = [(argv, mode) for argv in cheap if not argv[0].startswith("-") for mode in both]
    # A closed one is refused by main before it reads its arguments (cli/__init__.py), so
    # the same for every command: one case per way in (argparse's own exits, a command,
    # the one with the most work to refuse), each importing nothing
    closed = [argv for argv in every if argv[0] in ("--version", "--help", "reproduce")]
    bare += [(argv, "closed") for argv in [*closed, every[7]]]
    heavy = [(argv, "buffered") for argv in every if argv not in cheap]
    heavy += [(argv, "unbuffered") for argv in (every[7], every[8])]
    for argv, mode, code, err in run_cases(bare, light, heavy):
        assert code == 2, (argv, mode, code, err)
        assert err.count("\n") == 1 and err.startswith("plateimpact: error: standard output"), (
            argv,
            mode,
            err,
        )
        if mode == "closed":  # refused before any work
            assert "is closed" in err
        else:
            assert "No space left on device" in err
