"""Bad input fuzzing (issue 7): malformed command lines and damaged archives give a
one-line error and exit code 2, never a traceback, a hang or a partial write."""

from __future__ import annotations

import contextlib
import io
import re
import shutil
import tempfile
from pathlib import Path

import numpy as np
import pytest
from hypothesis import assume, given
from hypothesis import strategies as st

import plateimpact as pi
from plateimpact import limits, presets
from plateimpact.cli import main as cli

VALUES = st.sampled_from(
    [
        "0", "-1", "1", "3.5", "45", "89.99", "90", "1e400", "-1e400", "nan", "inf", "-0",
        "1e-300", "abc", "", " ", "2024-T3/3.18", "x/y", "0:10:3", "10:0:3", "1,2,,3",
        "5:6:0", "7:8:2.5", "0,45", "500,nan", "10:20:5", "dopri5", "segment", "nope",
        "--", "-", "1e3", "1_000", "0x10",
    ]
)  # fmt: skip
FLAGS = [
    "--preset", "--speed", "--obliquity", "--speeds", "--obliquities", "--thickness",
    "--a", "--b", "--pstar", "--alpha", "--radius", "--mass", "--integrator", "--failure",
    "--resistance", "--json", "--rtol", "--step",
]  # fmt: skip


def run_cli(argv: list[str]) -> tuple[int, str]:
    err = io.StringIO()
    with contextlib.redirect_stderr(err), contextlib.redirect_stdout(io.StringIO()):
        try:
            code = cli(argv)
        except SystemExit as exc:  # argparse's own errors
            code = exc.code
    return code, err.getvalue()


def assert_clean(code: int, err: str) -> None:
    assert code in (0, 2), (code, err)
    if code == 2:
        lines = err.strip().splitlines()
        assert len(lines) == 1 and "error" in lines[0] and "Traceback" not in err, err


@given(
    command=st.sampled_from(["run", "sweep", "crater"]),
    options=st.lists(st.tuples(st.sampled_from(FLAGS), VALUES), max_size=8),
)
def test_malformed_command_lines_give_one_line_errors(command, options):
    argv = [command]
    for flag, value in options:
        argv += [flag] if flag == "--json" else [flag, value]
    # Keep accidental valid sweeps small: a fuzz run must not hang on a legitimate job.
    assume(not (command == "sweep" and any(":" in v and not v.endswith(":3") for _, v in options)))
    assert_clean(*run_cli(argv))


class ArchiveBytes(bytes):
    """A file's bytes, shown by size (hypothesis prints the test's arguments)."""

    def __repr__(self) -> str:
        return f"<{len(self)} bytes>"


class ArchiveFiles(dict):
    """A valid archive's files by their path in its directory: the index ``a.h5`` and
    its data files ``a.h5.d/*.nc``."""

    def __repr__(self) -> str:
        return f"<archive of {len(self)} files>"

    @classmethod
    def read(cls, path: Path) -> ArchiveFiles:
        files = [path, *sorted((path.parent / f"{path.name}.d").iterdir())]
        return cls({str(f.relative_to(path.parent)): ArchiveBytes(f.read_bytes()) for f in files})

    def write(self, directory: str | Path, damaged: str = "", data: bytes = b"") -> Path:
        """Write the archive into ``directory``, the file ``damaged`` holding ``data``."""
        (Path(directory) / "a.h5.d").mkdir(parents=True)
        for name, content in self.items():
            (Path(directory) / name).write_bytes(data if name == damaged else content)
        return Path(directory) / "a.h5"


@pytest.fixture(scope="module")
def archive_files() -> ArchiveFiles:
    with tempfile.TemporaryDirectory() as directory:
        path = Path(directory) / "a.h5"
        study = pi.Study.grid(
            "f", ["2024-T3/3.18"], [0, 60], np.linspace(200, 900, 4), pi.Variant("v")
        )
        study.run(archive=path, craters=True)
        return ArchiveFiles.read(path)


def check_archive(files: ArchiveFiles, damaged: str, data: bytes) -> None:
    with tempfile.TemporaryDirectory() as directory:
        path = files.write(directory, damaged, data)
        assert_clean(*run_cli(["show", str(path)]))
        code, err = run_cli(["compare", str(path), "v", "v"])
        assert_clean(code, err)
        try:  # the Python API raises ArchiveError (or reads the run back whole)
            result = pi.Archive(path).results("v")
            assert len(result) == 8
        except (pi.ArchiveError, pi.UnknownNameError):
            pass


#: Which of the archive's files is damaged: the index, the study's scenes, the run.
WHICH = st.integers(0, 2)


@given(cut=st.floats(0.0, 1.0), which=WHICH)
def test_truncated_archives_give_one_line_errors(archive_files, cut, which):
    name = sorted(archive_files)[which]
    data = archive_files[name]
    check_archive(archive_files, name, data[: int(cut * len(data))])


def flipped(data: bytes, flips: list[tuple[float, int]]) -> bytes:
    damaged = bytearray(data)
    for where, mask in flips:
        damaged[min(int(where * len(damaged)), len(damaged) - 1)] ^= mask
    return bytes(damaged)


FLIPS = st.lists(st.tuples(st.floats(0.0, 1.0), st.integers(1, 255)), min_size=1, max_size=8)


@given(flips=FLIPS, which=WHICH)
def test_bit_flipped_archives_give_one_line_errors(archive_files, flips, which):
    name = sorted(archive_files)[which]
    check_archive(archive_files, name, flipped(archive_files[name], flips))


@pytest.fixture(scope="module")
def limits_archive_files(archive_files) -> ArchiveFiles:
    """The archive of ``archive_files`` with stored limits beside its study."""
    with tempfile.TemporaryDirectory() as directory:
        path = archive_files.write(directory)
        found = limits.along_speed(
            pi.Simulation.from_names(), presets.DEFAULT_SPHERE, presets.plate("2024-T3/3.18"),
            [0.0, 0.5], (100.0, 900.0), resolution=50.0,
        )  # fmt: skip
        limits.archive_limits(path, "l", found)
        return ArchiveFiles.read(path)


@given(flips=FLIPS, index=st.booleans())
def test_bit_flipped_archives_with_limits_give_one_line_errors(limits_archive_files, flips, index):
    name = "a.h5" if index else next(n for n in limits_archive_files if "/limits." in n)
    with tempfile.TemporaryDirectory() as directory:
        path = limits_archive_files.write(
            directory, name, flipped(limits_archive_files[name], flips)
        )
        for argv in (["show"], ["compare", "l", "l"], ["compare", "l", "l", "--json"]):
            assert_clean(*run_cli([argv[0], str(path), *argv[1:]]))
        try:  # the Python API raises ArchiveError (or reads the limits back whole)
            assert len(limits.read_limits(path, "l").lines) == 2
        except (pi.ArchiveError, pi.UnknownNameError):
            pass


def test_a_refused_run_writes_nothing(tmp_path):
    """An archive that cannot be extended is left exactly as it was, and no temporary file
    remains next to it."""
    path = tmp_path / "a.h5"
    path.write_bytes(b"not an archive at all")
    study = pi.Study.grid("f", ["2024-T3/3.18"], [0], [300.0], pi.Variant("v"))
    with pytest.raises(pi.ArchiveError):
        study.run(archive=path)
    assert path.read_bytes() == b"not an archive at all"
    assert sorted(p.name for p in tmp_path.iterdir()) == ["a.h5"]
    shutil.rmtree(tmp_path / "missing", ignore_errors=True)


def test_damaged_archive_structure_gives_archive_error(archive_files, tmp_path):
    """Found by the bit-flip fuzz: a flipped byte in the superblock's addresses made h5py
    raise RuntimeError ("addr overflow") while listing the runs, which escaped as a
    traceback. Every h5py error inside an open archive is now an ArchiveError.

    The byte is at a fixed offset, not a fraction of the file, so that the damage stays
    the same when the archive's size changes: byte 17 of a version-0 superblock is the
    high byte of the group B-tree's leaf K, which sends the group listing out of the
    file."""
    data = bytearray(archive_files["a.h5"])
    assert data[8] == 0  # superblock version 0
    data[17] ^= 11
    path = archive_files.write(tmp_path, "a.h5", bytes(data))
    code, err = run_cli(["show", str(path)])
    assert code == 2 and len(err.strip().splitlines()) == 1 and "damaged" in err
    with pytest.raises(pi.ArchiveError):
        pi.StudyResults.from_archive(path)


def test_damaged_run_attributes_give_archive_error(archive_files, tmp_path):
    """Found by the bit-flip fuzz: attributes carry no fletcher32 checksum, so a flipped
    byte in a run's JSON metadata escaped as a JSONDecodeError or a KeyError in `show`.
    Studies and runs now carry a digest of their attributes, checked on reading."""
    run = next(name for name in archive_files if ".v." in name)
    assert archive_files[run].count(b"integrator_version") == 1  # in the run's model attribute
    changed = archive_files[run].replace(b"integrator_version", b"integrator_versioX")
    path = archive_files.write(tmp_path, run, changed)
    code, err = run_cli(["show", str(path)])
    assert code == 2 and len(err.strip().splitlines()) == 1 and "attributes" in err
    with pytest.raises(pi.ArchiveError, match="digest"):
        pi.Archive(path).metadata("v")
    labels = archive_files["a.h5"].replace(b'["2024-T3/3.18"]', b'["2024-T3/3.19"]')
    assert labels != archive_files["a.h5"]  # in the study's attributes in the index
    path = archive_files.write(tmp_path / "labels", "a.h5", labels)
    with pytest.raises(pi.ArchiveError, match="digest"):
        pi.Archive(path).study()


SHOT_COLUMNS = [
    "impact_speed_m_s",
    "impact_obliquity_deg",
    "residual_speed_m_s",
    "exit_obliquity_deg",
    "outcome",
    "perforated",
    "weight",
    "radius_mm",
    "note",
]
CELLS = st.sampled_from(
    ["0", "500", "700", "900", "1200", "-3", "nan", "inf", "", "abc", "perforation", "ricochet",
     "embedment", "1e400", "45", "0.0", "350", "2000", '"x,y"', "1", "true"]
)  # fmt: skip


@given(
    header=st.lists(st.sampled_from(SHOT_COLUMNS), max_size=6),
    rows=st.lists(st.lists(CELLS, max_size=7), max_size=6),
)
def test_malformed_shot_files_give_one_line_errors(header, rows):
    with tempfile.TemporaryDirectory() as directory:
        path = Path(directory) / "shots.csv"
        lines = [",".join(header)] + [",".join(row) for row in rows]
        path.write_text("\n".join(lines) + "\n")
        argv = ["calibrate", str(path), "--thickness", "3.18", "--pstar", "3", "--alpha", "45"]
        assert_clean(*run_cli(argv))
        assert_clean(*run_cli(["validate", str(path), "--preset", "2024-T3/3.18"]))
        assert_clean(*run_cli(["v50", str(path), "--by-obliquity", "--bootstrap", "20"]))


PLATE_VALUES = st.one_of(
    st.sampled_from([3.18, 0.0, -1.0, float("nan"), float("inf"), 1e9, 45.0, 90.0]),
    st.sampled_from(["3.18", "", None, True, [], {}]),
)


@given(
    fields=st.dictionaries(
        st.sampled_from(
            ["format", "material", "thickness_mm", "pstar_mm", "alpha_deg", "a_N_m2", "b_kg_m3"]
        ),
        PLATE_VALUES,
    ),
    garbage=st.binary(max_size=20),
)
def test_malformed_plate_files_give_one_line_errors(fields, garbage):
    import json  # noqa: PLC0415

    with tempfile.TemporaryDirectory() as directory:
        for n, content in enumerate([json.dumps(fields).encode(), garbage]):
            path = Path(directory) / f"plate{n}.json"
            path.write_bytes(content)
            argv = ["run", "--plate-file", str(path), "--speed", "500", "--obliquity", "30"]
            assert_clean(*run_cli(argv))


#: What someone else's JSON may hold where a number or a name belongs.
JSON_LITERALS = st.sampled_from(
    ["[" * 40 + "]" * 40, "[" * 5000 + "]" * 5000, "1" * 401, "1" * 19, "1e400", "-1e400",
     "true", "null", '"x"', '"500"', "[]", "{}", "NaN", "Infinity", "-0", "0", "1e-400",
     '{"a": 1, "a": 2}', '"\\u202e\\n\\u001b[2J"', '"' + "x" * 10_000 + '"']
)  # fmt: skip
#: A key and its scalar value in compact JSON.
SCALAR = re.compile(r'"(\w+)": (-?[\d.eE+-]+|true|false|null|Infinity|"[^"]*")')


def _edited(text: str, edits: list[tuple[int, str, str]]) -> str:
    """``text`` with each edit applied at the scalar it picks (by index, modulo their
    number): its value replaced, its key given again before it, or its value nested."""
    for index, how, literal in edits:
        found = list(SCALAR.finditer(text))
        if not found:
            break
        match = found[index % len(found)]
        key, value = match.group(1), match.group(2)
        start, end = match.span()
        if how == "replace":
            pair = f'"{key}": {literal}'
        elif how == "duplicate":
            pair = f'"{key}": {literal}, "{key}": {value}'
        else:  # nest
            pair = f'"{key}": {"[" * 40}{value}{"]" * 40}'
        text = text[:start] + pair + text[end:]
    return text


@pytest.fixture(scope="module")
def run_record() -> str:
    """A ``run --json`` output, for the JSON fuzz to damage."""
    out = io.StringIO()
    with contextlib.redirect_stdout(out):
        code = cli(["run", "--preset", "2024-T3/3.18", "--speed", "500", "--obliquity", "45",
                    "--json"])  # fmt: skip
    assert code == 0
    return out.getvalue()


@given(
    edits=st.lists(
        st.tuples(
            st.integers(0, 1000), st.sampled_from(["replace", "duplicate", "nest"]), JSON_LITERALS
        ),
        min_size=1,
        max_size=3,
    ),
    wrap=st.sampled_from([0, 0, 1, 40, 100_000]),
)
def test_nested_duplicated_and_huge_json_gives_one_line_errors(run_record, edits, wrap):
    import json  # noqa: PLC0415

    record = json.loads(run_record)["inputs"]
    plate = pi.storage.plate_file.plate_to_dict(
        presets.plate("2024-T3/3.18"), registry=pi.default_registry()
    )
    with tempfile.TemporaryDirectory() as directory:
        for name, value in (("run.json", record), ("plate.json", plate)):
            text = _edited(json.dumps(value), edits)
            path = Path(directory) / name
            path.write_text("[" * wrap + text + "]" * wrap)
            if name == "run.json":
                argv = ["run", "--inputs", str(path)]
            else:
                argv = ["run", "--plate-file", str(path), "--speed", "500", "--obliquity", "30"]
            assert_clean(*run_cli(argv))
