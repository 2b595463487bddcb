"""An input file without end (``/dev/zero``) or with a field beyond reason is one line
and exit code 2 at every input flag: each reader reads at most what its file can hold
(16 MB of JSON, 1 MB for a P* table; a shot file a line of at most 65,536 characters at
a time), never the whole of it."""

from __future__ import annotations

import os
from pathlib import Path

import pytest
from test_output_files import assert_one_line, run_cli

ENDLESS = "/dev/zero"
SCENE = ["--speed", "500", "--obliquity", "30"]


@pytest.mark.skipif(not os.path.exists(ENDLESS), reason="no /dev/zero here")
@pytest.mark.parametrize(
    ("argv", "words"),
    [
        (["run", "--inputs", ENDLESS], "bytes of JSON"),
        (["run", "--plate-file", ENDLESS, *SCENE], "bytes of JSON"),
        (["validate", ENDLESS, "--preset", "2024-T3/3.18"], "longer than 65,536 characters"),
        (["v50", ENDLESS], "longer than 65,536 characters"),
        (["calibrate", ENDLESS, "--preset", "2024-T3/3.18"], "longer than 65,536 characters"),
        (["run", "--preset", "SAE1010/1.47", *SCENE, "--failure", "variable-pstar",
          "--pstar-table", ENDLESS], "bytes; a table"),
    ],
    ids=["run --inputs", "--plate-file", "validate", "v50", "calibrate", "--pstar-table"],
)  # fmt: skip
def test_an_endless_input_file_is_one_line(argv, words):
    code, out, err = run_cli(argv)
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
