"""The optional extras (pyproject.toml): without an extra's packages its feature says, in
one line, which extra to install (pi.MissingExtraError, an ImportError, in Python; exit
code 2 on the command line, naming the flag), and the commands run without the
packages of the review and sobol extras."""

from __future__ import annotations

import json
import shutil
import subprocess
import sys
from importlib import resources

import numpy as np
import pytest

import plateimpact as pi
from plateimpact import presets
from plateimpact.cli import main
from plateimpact.uncertainty import Uniform
from plateimpact.uncertainty.sensitivity import sobol_indices

SPHERE = presets.DEFAULT_SPHERE
#: The packages of the review and sobol extras, and what they bring.
HIDDEN = ("xarray", "pandas", "SALib")


def one_line_naming(message: str, *names: str) -> bool:
    return "\n" not in message and all(name in message for name in names)


@pytest.mark.parametrize(
    "method, missing",
    [("to_xarray", "xarray"), ("to_dataframe", "pandas"), ("to_dataframe", "xarray")],
)
def test_a_table_without_its_library_names_the_review_extra(monkeypatch, method, missing):
    batch = pi.SceneBatch.grid(SPHERE, presets.plate("2024-T3/3.18"), [300.0, 600.0], [0.0])
    monkeypatch.setitem(sys.modules, missing, None)  # import raises ImportError
    with pytest.raises(pi.MissingExtraError) as raised:
        getattr(batch, method)()
    assert isinstance(raised.value, ImportError)
    assert one_line_naming(str(raised.value), missing, "pip install 'plateimpact[review]'")


def test_sobol_indices_without_salib_name_the_sobol_extra_before_any_point_runs(monkeypatch):
    monkeypatch.setitem(sys.modules, "SALib", None)
    evaluated: list[object] = []

    def quantity(values: dict[str, np.ndarray]) -> np.ndarray:
        evaluated.append(values)
        return values["x"]

    inputs = {"x": Uniform(0.0, 1.0), "y": Uniform(0.0, 1.0)}
    with pytest.raises(ImportError) as raised:
        sobol_indices(inputs, quantity, 16, seed=1)
    assert evaluated == []
    assert one_line_naming(str(raised.value), "SALib", "pip install 'plateimpact[sobol]'")


def test_the_sobol_flag_without_salib_is_one_line_naming_the_flag_and_extra(
    tmp_path, capsys, monkeypatch
):
    spec = {
        "preset": "2024-T3/3.18",
        "at": {"obliquity_deg": 0.0},
        "inputs": {
            "speed_m_s": {"normal": {"mean": 392.0, "sd": 30.0}},
            "pstar_mm": {"uniform": {"low": 2.9, "high": 3.1}},
        },
    }
    path = tmp_path / "spec.json"
    path.write_text(json.dumps(spec))
    monkeypatch.setitem(sys.modules, "SALib", None)
    assert main(["uncertainty", str(path), "--sobol", "16"]) == 2
    err = capsys.readouterr().err
    assert err.startswith("plateimpact: error: --sobol: ")
    assert one_line_naming(err.rstrip("\n"), "SALib", "pip install 'plateimpact[sobol]'")


def test_compile_without_numba_is_one_line_naming_the_fast_extra(capsys, monkeypatch):
    monkeypatch.setitem(sys.modules, "numba", None)
    assert main(["compile"]) == 2
    captured = capsys.readouterr()
    assert captured.out == "" and captured.err.startswith("plateimpact: error: compile needs ")
    assert one_line_naming(captured.err.rstrip("\n"), "numba", "pip install 'plateimpact[fast]'")


#: Runs each command line of argv[1] (JSON) with the HIDDEN packages unimportable (an
#: import of one raises ImportError), then prints the exit codes.
WITHOUT_EXTRAS = f"""
import json, sys
for name in {HIDDEN!r}:
    sys.modules[name] = None
from plateimpact.cli import main
print(json.dumps([main(argv) for argv in json.loads(sys.argv[1])]))
"""


def test_the_commands_run_without_the_review_and_sobol_extras(quick_report, tmp_path):
    archive = tmp_path / "report" / "report.h5"
    shutil.copytree(quick_report, archive.parent)
    data = resources.files("plateimpact_studies.data")
    spec = tmp_path / "spec.json"
    spec.write_text(
        json.dumps(
            {
                "preset": "2024-T3/3.18",
                "at": {"obliquity_deg": 0.0},
                "inputs": {"speed_m_s": {"normal": {"mean": 392.0, "sd": 30.0}}},
                "samples": 64,
            }
        )
    )
    commands = [
        ["run", "--preset", "2024-T3/1.27", "--speed", "200", "--obliquity", "45", "--json"],
        ["sweep", "--preset", "SAE1010/1.47", "--speeds", "100:1500:8", "--obliquities",
         "0,45", "--csv", "sweep.csv"],
        ["map", "--preset", "2024-T3/1.27", "--speeds", "100:1000:4", "--obliquities",
         "0:60:4", "--csv", "map.csv"],
        ["validate", str(data / "shots_2024T3_3.18mm.csv"), "--preset", "2024-T3/3.18"],
        ["v50", str(data / "gonogo_SAE1010_1.47mm.csv"), "--by-obliquity", "--json",
         "--bootstrap", "50"],  # the bootstrap's code, at a twentieth of its default cost
        ["uncertainty", str(spec), "--json"],
        ["show", str(archive)],
        ["export", str(archive), "--run", "2024-T3_3.18mm/plugging", "--to", "run.nc"],
        ["export", str(archive), "--run", "2024-T3_3.18mm/plugging", "--to", "run.csv"],
        ["compare", str(archive), "2024-T3_3.18mm/plugging", "2024-T3_3.18mm/large-pstar"],
    ]  # fmt: skip
    done = subprocess.run(
        [sys.executable, "-c", WITHOUT_EXTRAS, json.dumps(commands)],
        cwd=tmp_path,
        capture_output=True,
        text=True,
    )
    assert done.returncode == 0, done.stderr[-2000:]
    codes = json.loads(done.stdout.strip().splitlines()[-1])
    assert dict(zip(map(" ".join, commands), codes, strict=True)) == {
        " ".join(argv): 0 for argv in commands
    }, done.stderr[-2000:]
    for made in ("sweep.csv", "map.csv", "run.nc", "run.csv"):
        assert (tmp_path / made).stat().st_size > 0
