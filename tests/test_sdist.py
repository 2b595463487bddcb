"""The source distribution: built from this tree with no warning, it carries every tracked
file a user or a packager needs (docs/, tests/, benchmarks/, studies/, the licence,
citation and changelog) and nothing a docs build or a test run leaves behind, and the
docs test passes from it unpacked, against the installed plateimpact.

The sdist is built with setuptools' own backend in a child process, without build
isolation (no network: the test extras bring setuptools), from a copy of this tree, so
that the build's egg-info never appears in the tree other tests import from.
"""

from __future__ import annotations

import os
import re
import shutil
import subprocess
import sys
import tarfile
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[1]

if not (ROOT / "pyproject.toml").is_file():
    pytest.skip(
        "not a source checkout (no pyproject.toml beside tests/): nothing to build an sdist from",
        allow_module_level=True,
    )

#: What a docs build makes in the tree (.gitignore); left out of the clean copy.
DOCS_BUILD = ("docs/_build", "docs/api/generated", "docs/gallery", "docs/sg_execution_times.rst")
#: What a docs build and a test run leave in a tree, planted in the used copy: the
#: manifest is tested on a used tree as well as on a clean clone.
LEFTOVERS = (
    "docs/_build/html/index.html",
    "docs/api/generated/plateimpact.Study.rst",
    "docs/gallery/notebook_objects.py",
    "docs/sg_execution_times.rst",
    "tests/__pycache__/test_docs.cpython-311.pyc",
    "docs/_ext/__pycache__/public_names.cpython-311.pyc",
    "framework/plateimpact/__pycache__/units.cpython-311.pyc",
)
#: Tracked but not shipped: the CI script and git's own file.
UNSHIPPED = {".ci/run", ".gitignore"}
#: What setuptools prints when a manifest line matches nothing or something is amiss.
WARNING = re.compile(
    r"(?i)\bwarn(ing)?\b|no previously-included|no files found|no directories found"
)
BUILD_SDIST = (
    "import sys; from setuptools import build_meta; print(build_meta.build_sdist(sys.argv[1]))"
)


def source_copy(destination: Path, *, used: bool) -> Path:
    """This tree's files and folders, without hidden ones, build products, a virtual
    environment someone made inside it or what a docs build made (a clean clone); with
    ``used``, the LEFTOVERS of a docs build and a test run planted in it."""

    def skipped(folder: str, names: list[str]) -> set[str]:
        here = Path(folder).relative_to(ROOT)
        at_root = here == Path(".")
        return {
            name
            for name in names
            if name.startswith(".")
            or name == "__pycache__"
            or str(here / name) in DOCS_BUILD
            or (at_root and (name in {"build", "dist"} or name.endswith(".egg-info")))
            or (at_root and (ROOT / name / "pyvenv.cfg").exists())
        }

    shutil.copytree(ROOT, destination, ignore=skipped)
    for leftover in LEFTOVERS if used else ():
        path = destination / leftover
        path.parent.mkdir(parents=True, exist_ok=True)
        path.write_bytes(b"")
    return destination


class Sdist:
    """An sdist built from a copy of this tree: what setuptools printed, the files it
    holds (relative to its top folder) and, unpacked, where its top folder is."""

    def __init__(self, work: Path, *, used: bool) -> None:
        source = source_copy(work / "source", used=used)
        built = subprocess.run(
            [sys.executable, "-c", BUILD_SDIST, str(work / "dist")],
            cwd=source,
            capture_output=True,
            text=True,
        )
        assert built.returncode == 0, built.stderr
        self.log = built.stdout + built.stderr
        archive = work / "dist" / built.stdout.splitlines()[-1]
        with tarfile.open(archive) as tar:
            (top,) = {Path(name).parts[0] for name in tar.getnames()}
            self.names = {
                str(Path(member.name).relative_to(top))
                for member in tar.getmembers()
                if member.isfile()
            }
            tar.extractall(work / "unpacked", filter="data")
        self.root = work / "unpacked" / top


@pytest.fixture(scope="module")
def sdist(tmp_path_factory: pytest.TempPathFactory) -> Sdist:
    """The sdist of a used tree."""
    return Sdist(tmp_path_factory.mktemp("sdist"), used=True)


def warnings_in(log: str) -> list[str]:
    return [line for line in log.splitlines() if WARNING.search(line)]


def test_the_sdist_builds_without_a_warning_from_a_clean_clone_and_a_used_tree(sdist, tmp_path):
    clean = Sdist(tmp_path, used=False)
    assert warnings_in(clean.log) == []
    assert warnings_in(sdist.log) == []
    assert clean.names == sdist.names  # what a docs build or a test run left changes nothing


def test_the_sdist_carries_docs_tests_benchmarks_studies_and_the_project_files(sdist):
    wanted = {
        "LICENSE",
        "CITATION.cff",
        "CHANGELOG.md",
        "README.md",
        "pyproject.toml",
        "docs/plugins.md",
        "docs/conf.py",
        "docs/examples/notebook_objects.py",
        "tests/test_docs.py",
        "tests/third_party/plateimpact_isotropic-0.1.dist-info/entry_points.txt",
        "benchmarks/throughput.py",
        "studies/reproduce.py",
        "studies/data/shots_2024T3_3.18mm.csv",
        "plugins/plateimpact_plugins/__init__.py",
        "framework/plateimpact/__init__.py",
    }
    assert wanted - sdist.names == set()


def test_the_sdist_leaves_out_what_builds_and_test_runs_leave_behind(sdist):
    assert sdist.names & set(LEFTOVERS) == set()
    assert [name for name in sdist.names if "__pycache__" in name] == []


def test_every_tracked_file_but_the_ci_script_ships(sdist):
    listed = subprocess.run(["git", "ls-files"], cwd=ROOT, capture_output=True, text=True)
    if listed.returncode != 0:
        pytest.skip("not a git checkout: no list of tracked files to compare with")
    tracked = {name for name in listed.stdout.splitlines() if (ROOT / name).is_file()}
    assert tracked - UNSHIPPED - sdist.names == set()


def test_the_docs_test_passes_from_the_unpacked_sdist(sdist, tmp_path):
    # -P: the unpacked folder is not put on sys.path (its egg-info would stand for the
    # installed distribution); the tests import the installed plateimpact.
    # --assert=plain: an assert that fails fails the same; pytest only skips rewriting
    # the unpacked modules (new to Python, so rewritten on every run: half a second)
    # for the values it would show of a failing one.
    env = {name: value for name, value in os.environ.items() if not name.startswith("PYTEST_")}
    ran = subprocess.run(
        [
            sys.executable,
            "-P",
            "-m",
            "pytest",
            "tests/test_docs.py",
            "-q",
            "-p",
            "no:xdist",
            "-p",
            "no:cacheprovider",
            "-o",
            "addopts=",
            "--assert=plain",
            "--basetemp",
            str(tmp_path / "basetemp"),
        ],
        cwd=sdist.root,
        env=env,
        capture_output=True,
        text=True,
    )
    assert ran.returncode == 0, ran.stdout[-3000:] + ran.stderr[-3000:]
    summary = ran.stdout.strip().splitlines()[-1]
    assert re.search(r"\b\d+ passed\b", summary) and not re.search(
        r"failed|error|skipped", summary
    ), summary
