"""An input file without end or with a field beyond reason is one line and exit code 2 at
every input flag: each reader reads at most what its file can hold (16 MB of JSON, 1 MB
for a P* table; a shot file a line of at most 65,536 characters at a time), never the
whole of it. Named pipes and device nodes a tarball can ship are refused before they are
opened; a pipe from the shell is read as a file is."""

from __future__ import annotations

import contextlib
import json
import os
import subprocess
import sys
import threading
from collections.abc import Iterator
from pathlib import Path

import pytest
from test_output_files import assert_one_line, run_cli

SCENE = ["--speed", "500", "--obliquity", "30"]


@contextlib.contextmanager
def endless_pipe() -> Iterator[str]:
    """``/dev/fd/N``: the read end of a pipe that a thread fills with zeros for as long
    as it is open (as ``<(yes)`` would), closed afterwards, which ends the thread."""
    read, write = os.pipe()
    os.set_inheritable(read, True)

    def fill() -> None:
        with contextlib.suppress(OSError), os.fdopen(write, "wb", buffering=0) as sink:
            block = bytes(1 << 16)
            while True:
                sink.write(block)  # BrokenPipeError once the read end is closed

    thread = threading.Thread(target=fill, daemon=True)
    thread.start()
    try:
        yield f"/dev/fd/{read}"
    finally:
        os.close(read)
        thread.join()


@pytest.mark.parametrize(
    ("argv", "words"),
    [
        (["run", "--inputs", "{}"], "bytes of JSON"),
        (["run", "--plate-file", "{}", *SCENE], "bytes of JSON"),
        (["validate", "{}", "--preset", "2024-T3/3.18"], "longer than 65,536 characters"),
        (["v50", "{}"], "longer than 65,536 characters"),
        (["calibrate", "{}", "--preset", "2024-T3/3.18"], "longer than 65,536 characters"),
        (["run", "--preset", "SAE1010/1.47", *SCENE, "--failure", "variable-pstar",
          "--pstar-table", "{}"], "bytes; a table"),
    ],
    ids=["run --inputs", "--plate-file", "validate", "v50", "calibrate", "--pstar-table"],
)  # fmt: skip
def test_an_endless_input_file_is_one_line(argv, words):
    with endless_pipe() as endless:
        code, out, err = run_cli([arg.replace("{}", endless) for arg in argv])
    assert_one_line(code, err, words)
    assert out == ""


def test_a_shot_file_line_beyond_reason_is_one_line(tmp_path: Path):
    path = tmp_path / "shots.csv"
    path.write_text(
        'impact_speed_m_s,impact_obliquity_deg,perforated\n"' + "x" * 200_000 + '",0,1\n'
    )
    for argv in (["v50", str(path)], ["validate", str(path), "--preset", "2024-T3/3.18"]):
        code, _, err = run_cli(argv)
        assert_one_line(code, err, "line 2", "longer than")


FIFO_FLAGS = {
    "run --inputs": ["run", "--inputs", "{}"],
    "--plate-file": ["run", "--plate-file", "{}", *SCENE],
    "validate": ["validate", "{}", "--preset", "2024-T3/3.18"],
    "v50": ["v50", "{}"],
    "calibrate": ["calibrate", "{}", "--preset", "2024-T3/3.18"],
    "--pstar-table": ["run", "--preset", "SAE1010/1.47", *SCENE, "--failure", "variable-pstar",
                      "--pstar-table", "{}"],
}  # fmt: skip


@pytest.mark.parametrize("flag", FIFO_FLAGS)
def test_a_device_shipped_as_an_input_file_is_one_line(flag):
    """/dev/zero stands for any device node a tarball could ship (a terminal would wait
    for typing): refused before it is read."""
    argv = [arg.replace("{}", "/dev/zero") for arg in FIFO_FLAGS[flag]]
    code, out, err = run_cli(argv)
    assert_one_line(code, err, "a device, not a file")


#: Runs each command line of argv[2] (JSON: {flag: argv}) with ``run_cli`` of
#: tests/test_output_files.py (argv[1] on sys.path), then prints {flag: [code, stderr]}.
EACH_COMMAND = """
import json, sys
sys.path.insert(0, sys.argv[1])
from test_output_files import run_cli
found = {flag: run_cli(argv) for flag, argv in json.loads(sys.argv[2]).items()}
print(json.dumps({flag: [code, err] for flag, (code, _, err) in found.items()}))
"""


@pytest.fixture(scope="module")
def fifo_refusals(tmp_path_factory) -> dict[str, list]:
    """{flag: [exit code, standard error]} of each FIFO_FLAGS command given a named pipe,
    all run in one child (were one to wait, the timeout, which a passing run never comes
    near, turns the hang into a failure rather than a stuck suite)."""
    fifo = tmp_path_factory.mktemp("fifo") / "shots.csv"
    os.mkfifo(fifo)
    commands = {
        flag: [arg.replace("{}", str(fifo)) for arg in argv] for flag, argv in FIFO_FLAGS.items()
    }
    done = subprocess.run(
        [sys.executable, "-c", EACH_COMMAND, str(Path(__file__).parent), json.dumps(commands)],
        capture_output=True, text=True, timeout=120, check=True,
    )  # fmt: skip
    return json.loads(done.stdout.strip().splitlines()[-1])


@pytest.mark.parametrize("flag", FIFO_FLAGS)
def test_a_named_pipe_shipped_as_an_input_file_is_one_line_never_a_wait(fifo_refusals, flag):
    """A tarball can hold a FIFO named like a shot or plate file; opening it for reading
    would wait for a writer forever. It is refused before the open, in one line."""
    assert_one_line(*fifo_refusals[flag], "a named pipe (FIFO)")


def test_a_pipe_from_the_shell_is_read(tmp_path):
    """Process substitution hands over a pipe through /dev/fd: read as a file is."""
    plate = tmp_path / "plate.json"
    plate.write_text(
        '{"format": "plateimpact-plate-1", "material": "x", "thickness_mm": 3.18, '
        '"a_N_m2": 1.01e9, "b_kg_m3": 1260, "pstar_mm": 3.0, "alpha_deg": 45}'
    )
    read, write = os.pipe()
    with os.fdopen(write, "wb") as sink:
        sink.write(plate.read_bytes())
    try:
        code, out, err = run_cli(["run", "--plate-file", f"/dev/fd/{read}", *SCENE])
    finally:
        os.close(read)
    assert code == 0, err
    from_file = run_cli(["run", "--plate-file", str(plate), *SCENE])[1]
    assert out.split(":", 1)[1] == from_file.split(":", 1)[1]  # all but the label
