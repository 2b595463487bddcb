"""Provenance: the source commit comes from the installed distribution's
direct_url.json (PEP 610), never from a repository that merely encloses site-packages."""

from __future__ import annotations

import importlib.metadata
import json
import os
import subprocess

import pytest

from plateimpact.storage import provenance

# -- the source commit ---------------------------------------------------------------


def git(directory, *args: str) -> str:
    clean = {k: v for k, v in os.environ.items() if not k.startswith("GIT_")}
    identity = ["-c", "user.name=t", "-c", "user.email=t@example.org", "-c", "commit.gpgsign=false"]
    done = subprocess.run(
        ["git", "-C", str(directory), *identity, *args],
        capture_output=True,
        text=True,
        check=True,
        env=clean,
    )
    return done.stdout.strip()


def checkout(path, *files: str) -> str:
    """A git repository at ``path`` with one commit (holding ``files``); its HEAD."""
    for name in ("README", *files):
        (path / name).parent.mkdir(parents=True, exist_ok=True)
        (path / name).write_text("x\n")
    git(path, "init", "-q")
    git(path, "add", ".")
    git(path, "commit", "-q", "-m", "one")
    return git(path, "rev-parse", "HEAD")


def installed(site, direct_url: dict | None) -> importlib.metadata.Distribution:
    """plateimpact installed into ``site`` (a package and its .dist-info), with this
    direct_url.json (None: installed from an index, which writes none)."""
    (site / "plateimpact").mkdir(parents=True)
    (site / "plateimpact" / "__init__.py").write_text("")
    info = site / "plateimpact-0.1.0.dist-info"
    info.mkdir()
    (info / "METADATA").write_text("Metadata-Version: 2.1\nName: plateimpact\nVersion: 0.1.0\n")
    if direct_url is not None:
        (info / "direct_url.json").write_text(json.dumps(direct_url))
    return importlib.metadata.PathDistribution(info)


@pytest.fixture
def install(monkeypatch):
    """Make importlib.metadata find the given distribution as plateimpact's."""
    real = importlib.metadata.distribution

    def use(distribution: importlib.metadata.Distribution | None) -> None:
        def find(name: str) -> importlib.metadata.Distribution:
            if name != "plateimpact":
                return real(name)
            if distribution is None:
                raise importlib.metadata.PackageNotFoundError(name)
            return distribution

        monkeypatch.setattr(importlib.metadata, "distribution", find)

    return use


def test_a_commit_pip_recorded_from_a_git_url_is_the_source_commit(tmp_path, install):
    commit = "0123456789abcdef0123456789abcdef01234567"
    url = {
        "url": "https://example.org/plateimpact.git",
        "vcs_info": {"vcs": "git", "commit_id": commit},
    }
    install(installed(tmp_path / "site", url))
    assert provenance.source_commit(tmp_path / "site" / "plateimpact") == commit


def test_an_install_from_a_local_checkout_asks_git_there(tmp_path, install):
    head = checkout(tmp_path / "src")
    install(installed(tmp_path / "site", {"url": (tmp_path / "src").as_uri(), "dir_info": {}}))
    assert provenance.source_commit(tmp_path / "site" / "plateimpact") == head


def test_an_editable_install_gives_its_checkouts_commit(tmp_path, install):
    head = checkout(tmp_path / "repo", "framework/plateimpact/__init__.py")
    url = {"url": (tmp_path / "repo").as_uri(), "dir_info": {"editable": True}}
    install(installed(tmp_path / "site", url))
    assert provenance.source_commit(tmp_path / "repo" / "framework" / "plateimpact") == head


@pytest.mark.parametrize("source", ["index", "unpacked", "inside the enclosing repository"])
def test_a_repository_enclosing_site_packages_is_never_asked(tmp_path, install, source):
    """site-packages inside a repository of its own (a project's .venv): git asked there
    answers that repository's commit, which says nothing about plateimpact's source."""
    enclosing = checkout(tmp_path / "project")
    site = tmp_path / "project" / ".venv" / "lib" / "site-packages"
    (tmp_path / "unpacked").mkdir()
    (tmp_path / "project" / "sub").mkdir()
    url = {
        "index": None,
        "unpacked": {"url": (tmp_path / "unpacked").as_uri(), "dir_info": {}},
        "inside the enclosing repository": {
            "url": (tmp_path / "project" / "sub").as_uri(),
            "dir_info": {},
        },
    }[source]
    install(installed(site, url))
    assert git(site / "plateimpact", "rev-parse", "HEAD") == enclosing  # the trap is set
    assert provenance.source_commit(site / "plateimpact") == "unknown"


def test_a_source_tree_on_the_path_gives_its_own_checkouts_commit(tmp_path, install):
    """Code that is not the installed distribution's (a checkout on PYTHONPATH): the
    checkout of this project that holds it; any other repository: unknown."""
    other = checkout(tmp_path / "installed-from")
    url = {"url": (tmp_path / "installed-from").as_uri(), "dir_info": {"editable": True}}
    install(installed(tmp_path / "site", url))
    head = checkout(tmp_path / "tree", "framework/plateimpact/__init__.py")
    assert head != other
    assert provenance.source_commit(tmp_path / "tree" / "framework" / "plateimpact") == head
    checkout(tmp_path / "elsewhere", "lib/plateimpact/__init__.py")
    assert provenance.source_commit(tmp_path / "elsewhere" / "lib" / "plateimpact") == "unknown"
    install(None)  # not installed at all
    assert provenance.source_commit(tmp_path / "tree" / "framework" / "plateimpact") == head
