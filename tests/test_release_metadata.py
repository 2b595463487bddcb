"""The version has one source, pyproject.toml: the installed metadata, ``__version__``,
CITATION.cff and the changelog's latest section say the same."""

from __future__ import annotations

import re
import tomllib
from importlib.metadata import version
from pathlib import Path

import pytest

import plateimpact

ROOT = Path(__file__).resolve().parents[1]


@pytest.fixture(scope="module")
def declared() -> str:
    if not (ROOT / "pyproject.toml").is_file():
        pytest.skip("not a source tree: no pyproject.toml")
    return tomllib.loads((ROOT / "pyproject.toml").read_text())["project"]["version"]


def test_installed_version_is_the_declared_one(declared):
    assert version("plateimpact") == plateimpact.__version__ == declared


def test_citation_and_changelog_name_the_declared_version(declared):
    citation = re.search(r"^version:\s*(\S+)\s*$", (ROOT / "CITATION.cff").read_text(), re.M)
    assert citation is not None and citation.group(1).strip("'\"") == declared
    latest = re.search(r"^## \[([^\]]+)\]", (ROOT / "CHANGELOG.md").read_text(), re.M)
    assert latest is not None and latest.group(1) == declared
