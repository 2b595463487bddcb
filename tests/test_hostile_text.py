"""Text from someone else's file never acts on the terminal: names, descriptions, hosts,
versions, plate labels and materials of an archive, a plate file's keys, a shot file's
cells, an inputs record's label, a P* table's header. Each prints as one inert line
(plateimpact.base.untrusted.printable: new lines, escape sequences, carriage returns and
bidirectional overrides escaped), in ``show``, ``compare``, ``run``, ``validate``, ``v50``
and every error message; no forged ``plateimpact: error:`` line ever starts a line.

The hostile archive is built with h5py, its attributes resealed (storage.hdf5.seal), so
that the archive reads as undamaged."""

from __future__ import annotations

import csv
import json
import warnings
from pathlib import Path

import h5py
import numpy as np
import pytest
from test_output_files import run_cli

import plateimpact as pi
from plateimpact import limits, presets
from plateimpact.base.errors import PlateImpactError, PlateImpactWarning
from plateimpact.base.untrusted import spreadsheet_safe
from plateimpact.storage.hdf5 import seal

#: A new line that forges an error line, an escape sequence, a carriage return and a
#: right-to-left override.
HOSTILE = "x\nplateimpact: error: forged\x1b[31mred\x1b]0;title\x07\r\u202eevil"
#: How it prints: every one of them escaped, on one line.
ESCAPED = "x\\nplateimpact: error: forged\\x1b[31mred\\x1b]0;title\\x07\\r\\u202eevil"


def assert_inert(text: str) -> None:
    """Every line printable (nothing a terminal acts on), none forged."""
    for line in text.splitlines():
        assert line.isprintable(), repr(line)
    assert not [line for line in text.splitlines()[1:] if line.startswith("plateimpact:")], text


def assert_one_inert_line(code: int, err: str) -> None:
    assert code == 2, err
    assert err.count("\n") == 1 and err.startswith("plateimpact: error: "), repr(err)
    assert_inert(err)


@pytest.fixture(scope="module")
def hostile_archive(tmp_path_factory) -> Path:
    """Two runs and stored limits, every name and text attribute hostile, resealed."""
    path = tmp_path_factory.mktemp("hostile") / "a.h5"
    study = pi.Study.grid(
        "s", plates=["2024-T3/3.18"], obliquities_deg=[45], speeds=[300.0, 900.0],
        variants=[pi.Variant("v"), pi.Variant("w", failure="intact")],
    )  # fmt: skip
    study.run(archive=path)
    found = limits.along_speed(
        pi.Simulation.from_names(), presets.DEFAULT_SPHERE, presets.plate("2024-T3/3.18"),
        [np.radians(45.0)], (300.0, 900.0), tolerance=5.0, resolution=50.0,
    )  # fmt: skip
    limits.archive_limits(path, "lim", found)
    data = []
    with h5py.File(path, "r+") as f:
        group = f["s"]
        group.attrs["description"] = HOSTILE
        seal(group)
        for run in ("v", "w"):
            link = group["runs"].get(run, getlink=True)
            data.append(path.parent / link.filename)
            del group["runs"][run]
            group["runs"][HOSTILE + run] = link
        scenes = path.parent / group.get("scenes", getlink=True).filename
        f.move("s", HOSTILE)
        link = f["limits"].get("lim", getlink=True)
        data.append(path.parent / link.filename)
        del f["limits"]["lim"]
        f["limits"][HOSTILE] = link
        seal(f["limits"])
    for file in data:
        with h5py.File(file, "r+") as d:
            for key in ("host", "start_time", "creation_time", "git_commit"):
                if key in d.attrs:
                    d.attrs[key] = HOSTILE
            d.attrs["versions"] = json.dumps({HOSTILE: HOSTILE, "plateimpact": HOSTILE})
            if "plate" in d.attrs:
                plate = json.loads(d.attrs["plate"])
                d.attrs["plate"] = json.dumps({**plate, "material": HOSTILE})
            seal(d)
    with h5py.File(scenes, "r+") as d:  # the plate label of each scene
        d["plate"][...] = np.array([HOSTILE] * d["plate"].shape[0], dtype=d["plate"].dtype)
    return path


def test_show_prints_an_archives_hostile_text_inert(hostile_archive):
    code, out, err = run_cli(["show", str(hostile_archive)])
    assert code == 0 and err == "", err
    assert_inert(out)
    lines = out.splitlines()
    # run names, plate labels, commit, versions, start time, host, the stored limits'
    # name, material, creation time and host: each there, escaped
    assert f"{ESCAPED}/{ESCAPED}v" in lines and f"{ESCAPED}/{ESCAPED}w" in lines
    assert f"  scenes: plates {ESCAPED}; impact_obliquity 45 deg" in out
    assert f"  run {ESCAPED} on {ESCAPED}" in lines
    assert f"limits/{ESCAPED}: limits along impact speed, 1 line(s)" in lines
    assert f"  plate {ESCAPED} 3.18 mm (" in out and f"  made {ESCAPED} on {ESCAPED}" in out


def test_errors_that_name_an_archives_hostile_runs_are_one_inert_line(hostile_archive):
    for argv in (
        ["compare", str(hostile_archive), "nosuch", "other"],
        ["export", str(hostile_archive), "--run", "nosuch", "--to", "x.csv"],
        ["plot", str(hostile_archive), "--run", "nosuch", "--out", "x.png"],
        ["compare", str(hostile_archive), f"{HOSTILE}/{HOSTILE}v", f"{HOSTILE}/{HOSTILE}w"],
    ):
        code, out, err = run_cli(argv)
        assert_one_inert_line(code, err)
        assert out == ""


def test_compare_prints_hostile_stored_limits_inert(hostile_archive):
    name = f"limits/{HOSTILE}"
    code, out, err = run_cli(["compare", str(hostile_archive), name, name])
    assert code == 0 and err == "", err
    assert_inert(out)
    assert out.startswith(f"limits/{ESCAPED} against limits/{ESCAPED}: 1 line(s)")


def test_the_one_line_error_escapes_what_a_message_carries(monkeypatch):
    from plateimpact.cli.commands import presets

    def hostile(*args):
        raise PlateImpactError(f"from a file: {HOSTILE}")

    monkeypatch.setattr(presets, "run", hostile)
    code, out, err = run_cli(["presets"])
    assert_one_inert_line(code, err)
    assert err == f"plateimpact: error: from a file: {ESCAPED}\n"


def test_a_warning_quoting_a_file_is_one_inert_line(monkeypatch):
    from plateimpact.cli.commands import presets

    def warns(*args):
        warnings.warn(f"skipped {HOSTILE}", PlateImpactWarning, stacklevel=1)
        return 0

    monkeypatch.setattr(presets, "run", warns)
    code, out, err = run_cli(["presets"])
    assert code == 0 and err == f"plateimpact: warning: skipped {ESCAPED}\n"


def test_an_inputs_records_hostile_label_prints_inert(tmp_path):
    code, out, _ = run_cli(["run", "--preset", "2024-T3/3.18", "--speed", "500",
                            "--obliquity", "45", "--json"])  # fmt: skip
    record = json.loads(out)
    record["inputs"]["label"] = HOSTILE
    path = tmp_path / "run.json"
    path.write_text(json.dumps(record))
    code, out, err = run_cli(["run", "--inputs", str(path)])
    assert code == 0 and err == "", err
    assert_inert(out)
    assert out.startswith(f"{ESCAPED}: 500 m/s at 45 deg -> embedment\n")


def plate_text(**changes: object) -> str:
    record = pi.storage.plate_file.plate_to_dict(
        presets.plate("2024-T3/3.18"), registry=pi.default_registry()
    )
    return json.dumps({**record, **changes})


@pytest.mark.parametrize(
    "text",
    [
        plate_text(**{HOSTILE: 1.0}),  # an unknown key
        plate_text(material=[HOSTILE]),  # not a string
        plate_text(format=HOSTILE),
        plate_text(a_N_m2=HOSTILE),  # a string for a number
        json.dumps([HOSTILE]),
    ],
)
def test_a_plate_files_hostile_text_in_an_error_is_one_inert_line(tmp_path, text):
    path = tmp_path / "plate.json"
    path.write_text(text)
    code, out, err = run_cli(["run", "--plate-file", str(path), "--speed", "500",
                              "--obliquity", "45"])  # fmt: skip
    assert_one_inert_line(code, err)


def shots_file(tmp_path: Path, source: str, weight: str = "1") -> Path:
    path = tmp_path / "shots.csv"
    rows = ["impact_speed_m_s,impact_obliquity_deg,perforated,weight,source"]
    # perforated above 450 m/s, but for one shot either side: a zone of mixed results
    perforated = {v: int((v > 450) != (v in (440, 480))) for v in range(300, 620, 20)}
    rows += [f"{v},45,{p},{weight},{json.dumps(source)}" for v, p in perforated.items()]
    path.write_text("\n".join(rows) + "\n")
    return path


def test_a_shot_files_hostile_source_and_cells_print_inert(tmp_path):
    path = shots_file(tmp_path, HOSTILE)
    for argv in (
        ["validate", str(path), "--preset", "2024-T3/3.18"],
        ["v50", str(path), "--bootstrap", "0"],
        ["validate", str(path), "--preset", "2024-T3/3.18", "--json"],
    ):
        code, out, err = run_cli(argv)
        assert code == 0 and err == "", err
        assert_inert(out)
    bad = shots_file(tmp_path, "ok", weight=HOSTILE.replace("\n", " "))
    for argv in (["validate", str(bad), "--preset", "2024-T3/3.18"], ["v50", str(bad)]):
        code, out, err = run_cli(argv)
        assert_one_inert_line(code, err)


def test_a_pstar_tables_hostile_header_and_cells_are_one_inert_line(tmp_path):
    table = tmp_path / "pstar.csv"
    for text in (
        f"{HOSTILE},b\n1,2\n",
        "obliquity_deg,ricochet_pstar_mm,perforation_pstar_mm,transition_start_m_s,"
        f"transition_end_m_s\n0,{json.dumps(HOSTILE)},4,300,330\n",
    ):
        table.write_text(text)
        code, out, err = run_cli(["run", "--preset", "SAE1010/1.47", "--speed", "500",
                                  "--obliquity", "45", "--failure", "variable-pstar",
                                  "--pstar-table", str(table)])  # fmt: skip
        assert_one_inert_line(code, err)


# -- CSV cells a spreadsheet would run -------------------------------------------------------

FORMULA = '=HYPERLINK("http://example.invalid","x")'


def test_a_formula_from_a_file_is_written_to_csv_as_text(tmp_path, monkeypatch):
    """A plate label from someone else's archive, or the name of a plate file they sent,
    that begins as a formula does reaches a CSV cell with a leading ' (spreadsheets show
    it as text, OWASP's rule for CSV injection): an exported run, a sweep."""
    path = tmp_path / "a.h5"
    study = pi.Study.grid("s", ["2024-T3/3.18"], [45], [300.0, 900.0], [pi.Variant("v")])
    study.run(archive=path)
    with h5py.File(path, "r") as f:
        scenes = path.parent / f["s"].get("scenes", getlink=True).filename
    with h5py.File(scenes, "r+") as d:
        d["plate"][...] = np.array([FORMULA] * d["plate"].shape[0], dtype=d["plate"].dtype)
    out = tmp_path / "v.csv"
    assert run_cli(["export", str(path), "--run", "v", "--to", str(out)])[0] == 0
    rows = list(csv.reader(out.read_text().splitlines()))
    assert [row[0] for row in rows[1:]] == ["'" + FORMULA] * 2
    monkeypatch.chdir(tmp_path)  # the sweep's label is the plate file's name as typed
    Path("@SUM(1+1).json").write_text(plate_text())
    argv = ["sweep", "--plate-file", "@SUM(1+1).json", "--speeds", "300,900",
            "--obliquities", "45", "--csv", "sweep.csv"]  # fmt: skip
    assert run_cli(argv)[0] == 0
    rows = list(csv.reader(Path("sweep.csv").read_text().splitlines()))
    assert {row[0] for row in rows[1:]} == {"'@SUM(1+1).json"}


@pytest.mark.parametrize(
    ("cell", "written"),
    [("=1+1", "'=1+1"), ("+A1", "'+A1"), ("-cmd", "'-cmd"), ("@x", "'@x"), ("\tx", "'\tx"),
     ("-1.5", "-1.5"), ("+2e3", "+2e3"), ("2024-T3/3.18", "2024-T3/3.18"), ("", "")],
)  # fmt: skip
def test_only_text_that_begins_as_a_formula_is_changed(cell, written):
    """Numbers (a signed one too) and ordinary labels are written as they are."""
    assert spreadsheet_safe(cell) == written
