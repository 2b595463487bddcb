"""Archives from someone else (issue 21): a tarball of ``a.h5``, ``a.h5.d/`` and
``a.h5.lock`` may hold symlinks and hard links at every level, FIFOs, links that point
outside, HDF5 links and storage that reach other files, and attributes resealed after
editing. Each is one line (exit 2) or handled: never a hang, a traceback, or a write or
delete outside the archive's own files."""

from __future__ import annotations

import fcntl
import hashlib
import json
import os
import shutil
import subprocess
import sys
from pathlib import Path

import h5py
import numpy as np
import pytest
from test_output_files import assert_one_line, run_cli

import plateimpact as pi
from plateimpact import limits, presets
from plateimpact.cli.commands import reproduce as archive_commands
from plateimpact.limits.archived import attributes_of
from plateimpact.storage import lock as locking
from plateimpact.storage.output import write_text

NOTES = b"my own notes, not the archive's\n"
DEAD = subprocess.run([sys.executable, "-c", "import os; print(os.getpid())"],
                      capture_output=True, text=True).stdout.strip()  # fmt: skip


def tiny_study(name: str = "w", variant: str = "v") -> pi.Study:
    return pi.Study.grid(name, ["2024-T3/3.18"], [0, 45], np.array([300.0, 900.0]),
                         pi.Variant(variant))  # fmt: skip


@pytest.fixture(scope="module")
def template(tmp_path_factory) -> Path:
    """An archive with study w (run v, with trajectories) and stored limits ``l``."""
    path = tmp_path_factory.mktemp("template") / "a.h5"
    tiny_study().run(archive=path, record_trajectory=True)
    found = limits.along_speed(
        pi.Simulation.from_names(), presets.DEFAULT_SPHERE, presets.plate("2024-T3/3.18"),
        np.radians([30.0]), (200.0, 800.0), resolution=100.0,
    )  # fmt: skip
    limits.archive_limits(path, "l", found)
    return path


@pytest.fixture
def archive(template, tmp_path) -> Path:
    """A fresh copy of the template in its own directory, without its lock file."""
    path = tmp_path / "a.h5"
    shutil.copyfile(template, path)
    shutil.copytree(pi.Archive(template).data, tmp_path / "a.h5.d")
    return path


@pytest.fixture(scope="module")
def result() -> pi.BatchResult:
    return tiny_study().run()["v"]


def recorded(path: Path, link: str) -> str:
    """The file name the index's external link ``link`` records (h5py alone)."""
    with h5py.File(path, "r") as f:
        return f.get(link, getlink=True).filename


def data_file(path: Path, link: str) -> Path:
    """The data file the index's link ``link`` names, in the archive's data directory."""
    return path.with_name(f"{path.name}.d") / Path(recorded(path, link)).name


def reseal(group: h5py.Group) -> None:
    """Recompute a group's digest as docs/archive.md describes it (SHA-256 of the other
    attributes, netCDF's own ``_`` ones aside, as JSON with sorted keys): what anyone
    editing an archive can do."""
    plain = {}
    for key, value in group.attrs.items():
        if key.startswith("_") or key == "attributes_sha256":
            continue
        if isinstance(value, np.generic) or (np.ndim(value) == 1 and np.size(value) == 1):
            value = value.item() if isinstance(value, np.generic) else value[0].item()
        plain[key] = value
    text = json.dumps(plain, sort_keys=True)
    group.attrs["attributes_sha256"] = hashlib.sha256(text.encode()).hexdigest()


def append_run(path: Path, result: pi.BatchResult, name: str = "x") -> str:
    return pi.Archive(path, wait=0.0).append_run(
        tiny_study(), pi.Variant(name), result, {"note": "x"}
    )


# -- the lock ------------------------------------------------------------------------------


def _symlink(lock: Path, notes: Path) -> None:
    lock.symlink_to(notes)


def _hard_link(lock: Path, notes: Path) -> None:
    os.link(notes, lock)


def _fifo(lock: Path, notes: Path) -> None:
    os.mkfifo(lock)


def _directory(lock: Path, notes: Path) -> None:
    lock.mkdir()


@pytest.mark.parametrize("make", [_symlink, _hard_link, _fifo, _directory])
def test_a_shipped_lock_is_never_written_and_refused_before_any_run(archive, make, monkeypatch):
    notes = archive.parent / "notes.txt"
    notes.write_bytes(NOTES)
    make(archive.with_name("a.h5.lock"), notes)
    before = archive.read_bytes()
    monkeypatch.setattr("plateimpact.run.simulation.run_chunk", _no_run)  # refused before any run
    with pytest.raises(pi.ArchiveError, match=r"lock .*a\.h5\.lock is (a symbolic|a second|not a)"):
        tiny_study(variant="new").run(archive=archive)
    code, _, err = run_cli(["limits", "--preset", "2024-T3/3.18", "--obliquities", "0",
                            "--archive", str(archive)])  # fmt: skip
    assert_one_line(code, err, "a.h5.lock")
    assert notes.read_bytes() == NOTES and archive.read_bytes() == before


def _no_run(*args, **kwargs):
    raise AssertionError("a scene ran before the archive was refused")


def test_busy_never_follows_a_link(archive):
    """A link to a file someone holds a lock on is not this archive's lock."""
    held = archive.parent / "held"
    held.write_bytes(b"")
    fd = os.open(held, os.O_RDWR)
    fcntl.flock(fd, fcntl.LOCK_EX)
    try:
        lock = archive.with_name("a.h5.lock")
        lock.symlink_to(held)
        assert locking.busy(lock) is False
        os.unlink(lock)
        os.link(held, lock)
        assert locking.busy(lock) is False  # a second name of another file neither
    finally:
        os.close(fd)


# -- the data directory ------------------------------------------------------------------


def test_a_data_directory_that_is_a_symlink_is_refused_and_nothing_there_deleted(archive, result):
    mine = archive.parent / "mydata"
    (archive.parent / "a.h5.d").rename(mine)
    (archive.parent / "a.h5.d").symlink_to("mydata")
    own = mine / "notes.0123abcd.nc"  # a name of the archive's pattern, no index names it
    own.write_bytes(NOTES)
    listing = sorted(p.name for p in mine.iterdir())
    with pytest.raises(pi.ArchiveError, match="data directory .* is a symbolic link"):
        append_run(archive, result)
    with pytest.raises(pi.ArchiveError, match="symbolic link"):
        tiny_study(variant="new").run(archive=archive)
    for argv in (["show", str(archive)], ["export", str(archive), "--run", "v", "--to",
                                          str(archive.parent / "v.csv")]):  # fmt: skip
        code, _, err = run_cli(argv)
        assert_one_line(code, err, "symbolic link")
    assert sorted(p.name for p in mine.iterdir()) == listing and own.read_bytes() == NOTES


def test_cleanup_deletes_only_what_it_can_prove_a_writer_made(archive, result):
    data = archive.parent / "a.h5.d"
    outside = archive.parent / "outside.nc"
    outside.write_bytes(NOTES)
    foreign = {
        "link.0123abcd.nc": lambda p: p.symlink_to(outside),
        "hard.0123abcd.nc": lambda p: os.link(outside, p),
        "dir.0123abcd.nc": lambda p: p.mkdir(),
        "fifo.0123abcd.nc": lambda p: os.mkfifo(p),
        "README.txt": lambda p: p.write_bytes(NOTES),
        ".w.v.0123abcd.nc.tmp": lambda p: p.write_bytes(NOTES),  # not of the pattern
        f".w.v.0123abcd.nc.{os.getppid()}.0123abcd.tmp": lambda p: p.write_bytes(NOTES),  # live
        f".a.h5.{os.getppid()}.abcdefgh.tmp": lambda p: p.write_bytes(NOTES),  # live, beside
    }
    for name, make in foreign.items():
        make((archive.parent if name.startswith(".a.h5") else data) / name)
    orphan = data / "gone.0123abcd.nc"  # a writer's file no index names: removed
    orphan.write_bytes(NOTES)
    dead = data / f".w.v.0123abcd.nc.{DEAD}.0123abcd.tmp"  # a dead writer's: removed
    dead.write_bytes(NOTES)
    append_run(archive, result)
    for name in foreign:
        assert os.path.lexists((archive.parent if name.startswith(".a.h5") else data) / name)
    assert not orphan.exists() and not dead.exists() and outside.read_bytes() == NOTES
    assert set(pi.Archive(archive).runs()) == {"w/v", "w/x"}


# -- links that point outside --------------------------------------------------------------


@pytest.mark.parametrize("where", ["relative", "absolute", "dots"])
def test_an_index_link_outside_the_data_directory_is_refused_by_writers(archive, result, where):
    scenes = data_file(archive, "w/scenes")
    elsewhere = archive.parent / "elsewhere"
    elsewhere.mkdir()
    moved = elsewhere / scenes.name
    scenes.rename(moved)  # the only copy is outside
    target = {
        "relative": f"../{archive.parent.name}/elsewhere/{scenes.name}",
        "absolute": str(moved),
        "dots": f"a.h5.d/../elsewhere/{scenes.name}",
    }[where]
    with h5py.File(archive, "a") as f:
        del f["w/scenes"]
        f["w/scenes"] = h5py.ExternalLink(target, "/")
    before = archive.read_bytes()
    with pytest.raises(pi.ArchiveError, match="not a file of its own data directory"):
        append_run(archive, result)
    with pytest.raises(pi.ArchiveError, match="not a file of its own data directory"):
        tiny_study(variant="new").check_archive(archive)
    code, _, err = run_cli(["show", str(archive)])
    assert_one_line(code, err, "not a file of its own data directory")
    assert archive.read_bytes() == before


def test_a_data_file_that_is_a_symlink_fifo_or_directory_is_one_line(archive):
    run = data_file(archive, "w/runs/v")
    copy = archive.parent / "copy.nc"
    shutil.copyfile(run, copy)
    for make, words in [
        (lambda: run.symlink_to(copy), "symbolic link"),
        (lambda: os.mkfifo(run), "not a regular file"),  # opened without blocking
        (lambda: run.mkdir(), "not a regular file"),
    ]:
        if run.is_dir() and not run.is_symlink():
            run.rmdir()
        else:
            run.unlink()
        make()
        code, _, err = run_cli(["show", str(archive)])
        assert_one_line(code, err, words)
        with pytest.raises(pi.ArchiveError, match=words):
            pi.Archive(archive).results("v")


def _secret(directory: Path) -> Path:
    """An HDF5 file of someone's with four numbers in it."""
    secret = directory / "secret.h5"
    with h5py.File(secret, "w") as f:
        f["secret"] = np.array([1111.0, 2222.0, 3333.0, 4444.0])
        f["bytes"] = np.array([1111.0, 2222.0, 3333.0, 4444.0])
    return secret


FORMAT1 = Path(__file__).parent / "data" / "format1.h5"


def test_a_format_1_archive_with_an_external_link_is_neither_read_nor_copied(tmp_path):
    path = tmp_path / "old.h5"
    shutil.copyfile(FORMAT1, path)
    _secret(tmp_path)
    with h5py.File(path, "a") as f:
        del f["v1/runs/plugging/results/exit_speed"]
        f["v1/runs/plugging/results/exit_speed"] = h5py.ExternalLink("secret.h5", "/secret")
    before = path.read_bytes()
    table = tmp_path / "x.csv"
    for argv in (["show", str(path)], ["export", str(path), "--run", "v1/plugging", "--to",
                 str(table)], ["upgrade", str(path)]):  # fmt: skip
        code, _, err = run_cli(argv)
        assert_one_line(code, err, "external link", "secret.h5")
    assert not table.exists() and path.read_bytes() == before
    assert not (tmp_path / "old.h5.format1.h5").exists()


@pytest.mark.parametrize("kind", ["external storage", "virtual", "external link", "soft link"])
def test_a_data_file_reaching_other_files_is_refused(archive, kind):
    run = data_file(archive, "w/runs/v")
    secret = _secret(archive.parent)
    with h5py.File(run, "a") as f:
        del f["exit_speed"]
        if kind == "external storage":  # raw bytes from another file: 8-byte floats
            with h5py.File(secret, "r") as s:
                offset = s["bytes"].id.get_offset()
            f.create_dataset("exit_speed", shape=(4,), dtype="f8",
                             external=[(str(secret), offset, 32)])  # fmt: skip
        elif kind == "virtual":
            layout = h5py.VirtualLayout(shape=(4,), dtype="f8")
            layout[:] = h5py.VirtualSource(str(secret), "secret", shape=(4,))
            f.create_virtual_dataset("exit_speed", layout)
        elif kind == "external link":
            f["exit_speed"] = h5py.ExternalLink(str(secret), "/secret")
        else:
            f["exit_speed"] = h5py.SoftLink("/exit_obliquity")
    words = {"external storage": "keeps its data in other files", "virtual": "virtual dataset",
             "external link": "external link", "soft link": "soft link"}[kind]  # fmt: skip
    with pytest.raises(pi.ArchiveError, match=words):
        pi.Archive(archive).results("v")
    table = archive.parent / "x.csv"
    code, _, err = run_cli(["export", str(archive), "--run", "v", "--to", str(table)])
    assert_one_line(code, err, words)
    assert not table.exists()


def test_a_soft_link_in_the_index_is_refused(archive):
    with h5py.File(archive, "a") as f:
        f["w/runs/alias"] = h5py.SoftLink("/w/runs/v")
    code, _, err = run_cli(["show", str(archive)])
    assert_one_line(code, err, "w/runs/alias is a soft link")


@pytest.mark.parametrize(
    "name", ["a.h5.d/x\n.0123abcd.nc", "a.h5.d/../a.h5", "/etc/passwd", "a.h5.d/sub/x.0123abcd.nc",
             "..d/x.0123abcd.nc\x1b[31m"],
)  # fmt: skip
def test_recorded_names_that_are_not_the_archives_own_are_one_line(archive, name):
    with h5py.File(archive, "a") as f:
        del f["w/runs/v"]
        f["w/runs/v"] = h5py.ExternalLink(name, "/")
    code, _, err = run_cli(["show", str(archive)])
    assert_one_line(code, err, "not a file of its own data directory")
    assert "\x1b" not in err


# -- temporaries of other archives and of live writers -------------------------------------


def test_cleanup_takes_no_temporary_of_another_archive_or_a_live_writer(tmp_path, result):
    others = [
        f".run1.h5.{os.getppid()}.abcdefgh.tmp",  # a live writer of run1.h5 (glob run[1])
        f".run1.h5.{DEAD}.abcdefgh.tmp",  # a dead one: its own writer's to remove
        f".run[1].h5.x.h5.{DEAD}.abcdefgh.tmp",  # of the archive run[1].h5.x.h5
        f".run[1].h5.{os.getppid()}.abcdefgh.tmp",  # a live writer of this very archive
    ]
    for name in others:
        (tmp_path / name).write_bytes(NOTES)
    mine = tmp_path / f".run[1].h5.{DEAD}.abcdefgh.tmp"  # a dead writer of this archive
    mine.write_bytes(NOTES)
    tiny_study().run(archive=tmp_path / "run[1].h5")
    assert all((tmp_path / name).read_bytes() == NOTES for name in others)
    assert not mine.exists()


def test_an_output_writer_takes_no_temporary_of_another_target(tmp_path):
    """``a`` and ``a.4194303``: the other's temporary starts with ``.a.4194303.``, where a
    loose parse would read a (dead) process 4194303."""
    other = tmp_path / f".a.4194303.{os.getppid()}.abcdefgh.tmp"
    other.write_bytes(NOTES)
    write_text(tmp_path / "a", "new\n", "--csv")
    assert other.read_bytes() == NOTES and (tmp_path / "a").read_text() == "new\n"


# -- a renamed archive -------------------------------------------------------------------


def test_a_renamed_archive_takes_new_runs_in_its_existing_study(archive, monkeypatch):
    renamed = archive.with_name("b.h5")
    archive.rename(renamed)
    (archive.parent / "a.h5.d").rename(archive.parent / "b.h5.d")
    study = pi.Study("w", tiny_study().scenes, [pi.Variant("v"), pi.Variant("new")],
                     tiny_study().plate_labels)  # fmt: skip
    study.check_archive(renamed, resume=True)
    study.run(archive=renamed, resume=True)
    archive_b = pi.Archive(renamed)
    assert archive_b.runs() == ["w/v", "w/new"]
    assert recorded(renamed, "w/runs/new").startswith("b.h5.d/")  # the current name
    np.testing.assert_array_equal(
        archive_b.results("new").exit_speed, tiny_study().run()["v"].exit_speed
    )
    data_file(renamed, "w/runs/new").unlink()  # refused before any scene runs
    data_file(renamed, "w/scenes").unlink()
    monkeypatch.setattr("plateimpact.run.simulation.run_chunk", _no_run)
    with pytest.raises(pi.ArchiveError, match="is missing"):
        study.run(archive=renamed, overwrite=True)


# -- attributes someone edited and resealed ----------------------------------------------

DEEP = "[" * 100_000 + "]" * 100_000


def _edit(path: Path, where: str, key: str, value: object, data: str | None = None) -> None:
    target = data_file(path, data) if data else path
    with h5py.File(target, "a") as f:
        group = f[where]
        group.attrs[key] = value
        reseal(group)


@pytest.mark.parametrize(
    ("where", "key", "value", "data", "words"),
    [
        ("w", "plate_labels", '{"a": 1}', None, "plate_labels holds an object, not a list"),
        ("w", "plate_labels", "[1, 2]", None, "plate_labels is not a list of text"),
        ("w", "plate_labels", DEEP, None, "nested more than"),
        ("w", "variants", "[1]", None, "a variant is int, not an object"),
        ("w", "variants", '[{"name": "v", "bogus": 1}]', None, "not a variant"),
        ("w", "description", 7, None, "attribute description is int, not text"),
        ("/", "variant", '"v"', "w/runs/v", "variant holds text, not an object"),
        ("/", "variant", DEEP, "w/runs/v", "nested more than"),
        ("/", "model", "[]", "w/runs/v", "model holds a list, not an object"),
        ("/", "versions", '{"a": 1, "a": 2}', "w/runs/v", "appears twice"),
        ("/", "failure_state_units", DEEP, "w/runs/v", "nested more than"),
        ("/", "wall_time_s", "fast", "w/runs/v", "wall_time_s is 'fast', not a finite number"),
        ("/", "host", 42, "w/runs/v", "attribute host is int, not text"),
    ],
)
def test_resealed_attributes_of_the_wrong_type_are_one_line(archive, where, key, value, data,
                                                            words):  # fmt: skip
    _edit(archive, where, key, value, data)
    code, _, err = run_cli(["show", str(archive)])
    assert_one_line(code, err, words)


@pytest.mark.parametrize(
    ("key", "value", "words"),
    [("plate", "[]", "plate"), ("model", DEEP, "nested more than"), ("plate", DEEP, "nested"),
     ("regimes", "[[[", "not valid JSON"), ("tolerance", "x", "tolerance")],
)  # fmt: skip
def test_resealed_attributes_of_stored_limits_are_one_line(archive, key, value, words):
    _edit(archive, "/", key, value, "limits/l")
    with pytest.raises(pi.ArchiveError, match=words):
        attributes_of(archive, "l")  # what listings read
    if key != "regimes":  # what reading them back reads
        with pytest.raises(pi.ArchiveError, match=words):
            limits.read_limits(archive, "l")
    code, _, err = run_cli(["show", str(archive)])
    assert_one_line(code, err, words)


def test_resealed_failure_state_units_cannot_break_an_export(archive):
    _edit(archive, "/", "failure_state_units", DEEP, "w/runs/v")
    code, _, err = run_cli(["export", str(archive), "--run", "v", "--to",
                            str(archive.parent / "v.nc")])  # fmt: skip
    assert_one_line(code, err, "nested more than")


def test_a_resealed_variant_cannot_break_a_resumed_study(archive):
    _edit(archive, "/", "variant", '{"name": 3}', "w/runs/v")
    with pytest.raises(pi.ArchiveError, match="not a variant"):
        tiny_study().run(archive=archive, resume=True)


# -- datasets of the wrong kind, shape or size --------------------------------------------


def _replace(path: Path, link: str, name: str, **dataset) -> None:
    with h5py.File(data_file(path, link), "a") as f:
        del f[name]
        f.create_dataset(name, **dataset)


@pytest.mark.parametrize(
    ("name", "dataset", "words"),
    [
        ("exit_speed", {"data": np.array(["a", "b", "c", "d"], dtype="S1")}, "where numbers"),
        ("outcome", {"data": np.array([1, 2, 3], dtype=np.int8)}, "has shape (3,), not (4,)"),
        ("outcome", {"data": np.array([1, 2, 9, 1], dtype=np.int8)}, "codes other than"),
        ("exit_speed", {"data": np.zeros((2, 2))}, "not (4,)"),
        ("trajectory_count", {"data": np.array([-5, 1, 2, 2])}, "negative count"),
        ("trajectory_count", {"data": np.full(4, 250_000_000_000)}, "more than its file holds"),
    ],
)
def test_datasets_of_the_wrong_kind_shape_or_size_are_one_line(archive, name, dataset, words):
    if "full" in words or "holds" in words:  # every sample column declares 10**12 values
        with h5py.File(data_file(archive, "w/runs/v"), "a") as f:
            for column in [k for k in f if k.startswith("trajectory_") and k != name]:
                if column != "trajectory_sample":
                    del f[column]
                    f.create_dataset(column, shape=(10**12,), dtype="f8", chunks=(1024,))
    _replace(archive, "w/runs/v", name, **dataset)
    with pytest.raises(pi.ArchiveError, match=words.replace("(", r"\(").replace(")", r"\)")):
        pi.Archive(archive).results("v")


def test_plate_labels_that_are_not_text_are_one_line(archive):
    _replace(archive, "w/scenes", "plate", data=np.arange(4.0))
    code, _, err = run_cli(["show", str(archive)])
    assert_one_line(code, err, "plate")


def _top_level_dataset(f: h5py.File) -> None:
    f["zz"] = np.arange(3)


def _runs_a_dataset(f: h5py.File) -> None:
    del f["w/runs"]
    f["w/runs"] = np.arange(3)


def _version_text(f: h5py.File) -> None:
    f.attrs["format_version"] = "2"


@pytest.mark.parametrize(
    ("damage", "words"),
    [(_top_level_dataset, "/zz is not a group"), (_runs_a_dataset, "/w/runs is not a group"),
     (_version_text, "format version '2'")],
)  # fmt: skip
def test_an_index_of_another_shape_is_one_line_for_readers_and_writers(archive, result, damage,
                                                                        words):  # fmt: skip
    with h5py.File(archive, "a") as f:
        damage(f)
    before = archive.read_bytes()
    code, _, err = run_cli(["show", str(archive)])
    assert_one_line(code, err, words)
    with pytest.raises(pi.ArchiveError):
        append_run(archive, result)
    assert archive.read_bytes() == before


def test_reproduce_refuses_a_shipped_lock_before_any_run(tmp_path, monkeypatch):
    out = tmp_path / "report"
    out.mkdir()
    notes = tmp_path / "notes.txt"
    notes.write_bytes(NOTES)
    (out / "report.h5.lock").symlink_to(notes)
    monkeypatch.setattr(archive_commands, "study_collection", lambda name: _no_run)
    code, _, err = run_cli(["reproduce", "--out", str(out)])
    assert_one_line(code, err, "--out", "report.h5.lock", "symbolic link")
    assert notes.read_bytes() == NOTES
