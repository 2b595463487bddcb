"""Provenance: what a run records besides its numbers: its inputs, the versions and the
source commit (docs/archive.md)."""

from __future__ import annotations

import datetime as dt
import json
import os
import platform
import socket
import subprocess
import time
import warnings
from collections.abc import Mapping
from importlib import metadata as importlib_metadata
from pathlib import Path
from typing import Any
from urllib.parse import urlparse
from urllib.request import url2pathname

from ..base.errors import PlateImpactWarning
from ..base.parameters import Parameter
from ..model.bodies import Plate, Sphere
from ..run.simulation import Simulation
from ..run.variant import Variant
from ..storage.plate_file import plate_to_dict
from . import inputs
from .code import plugins_record

PACKAGES = ("plateimpact", "numpy", "scipy", "attrs", "pluggy", "h5py")


#: The distribution whose source commit runs record.
DISTRIBUTION = "plateimpact"
#: The package directory of the running plateimpact.
PACKAGE_DIR = Path(__file__).resolve().parents[1]
#: Where the package sits in a checkout of this project (pyproject.toml's package-dir).
PACKAGE_IN_CHECKOUT = ("framework", "plateimpact")


#: How long git may take to name a checkout's HEAD [s]: only a guard against a git that
#: hangs (a dead network mount), far above the milliseconds ``rev-parse`` takes on a busy
#: machine; when it fires, the commit is recorded as "unknown" and a warning says so.
GIT_TIMEOUT = 60.0


def _git(directory: Path, *args: str) -> list[str] | None:
    """git's output lines in ``directory``, or None if git cannot answer. GIT_DIR and its
    kin are dropped from the environment: they would point git at another repository."""
    environment = {k: v for k, v in os.environ.items() if not k.startswith("GIT_")}
    try:
        out = subprocess.run(
            ["git", "-C", str(directory), *args],
            capture_output=True,
            text=True,
            timeout=GIT_TIMEOUT,
            check=True,
            env=environment,
        )
    except subprocess.TimeoutExpired:
        warnings.warn(
            f"git gave no answer in {directory} within {GIT_TIMEOUT:g} s; the source commit "
            "is recorded as unknown",
            PlateImpactWarning,
            stacklevel=2,
        )
        return None
    except (OSError, subprocess.SubprocessError):
        return None
    return out.stdout.split()


def _checkout_head(top: Path, package: Path | None = None) -> str:
    """The HEAD commit of the git checkout whose top directory is ``top`` (and that holds
    ``package`` at PACKAGE_IN_CHECKOUT, if given); "unknown" for anything else, such as
    a repository that merely encloses ``top``."""
    found = _git(top, "rev-parse", "--show-toplevel", "HEAD")
    if found is None or len(found) != 2:
        return "unknown"
    toplevel, head = Path(found[0]).resolve(), found[1]
    if toplevel != top.resolve():
        return "unknown"
    if package is not None and toplevel.joinpath(*PACKAGE_IN_CHECKOUT) != package:
        return "unknown"
    return head


def _direct_url(distribution: importlib_metadata.Distribution) -> dict[str, Any]:
    """The distribution's direct_url.json (PEP 610), or {} (installed from an index)."""
    try:
        data = json.loads(distribution.read_text("direct_url.json") or "{}")
    except (OSError, ValueError):
        return {}
    return data if isinstance(data, dict) else {}


def _local_directory(url: object) -> Path | None:
    """The directory a file:// URL names, if it is one."""
    if not (isinstance(url, str) and url.startswith("file://")):
        return None
    path = Path(url2pathname(urlparse(url).path)).resolve()
    return path if path.is_dir() else None


def source_commit(package_dir: Path | None = None) -> str:
    """The commit of the source the running plateimpact came from; "unknown" if not known.

    Read from the installed distribution's direct_url.json (PEP 610): the commit pip
    recorded for an install from a git URL (``vcs_info.commit_id``); for an install from
    a local directory (editable or not, ``url`` file:///path), the HEAD of that directory
    if it is itself a git checkout (for a non-editable install: at the time of the run).
    A package that is not the installed distribution's (a source tree on PYTHONPATH)
    gives the HEAD of the checkout of this project that holds it. Never the commit of a
    repository that merely encloses site-packages or the source directory.
    """
    package = (package_dir or PACKAGE_DIR).resolve()
    try:
        distribution = importlib_metadata.distribution(DISTRIBUTION)
    except importlib_metadata.PackageNotFoundError:
        distribution = None
    if distribution is not None:
        info = _direct_url(distribution)
        source = _local_directory(info.get("url"))
        dir_info = info.get("dir_info")
        editable = isinstance(dir_info, dict) and dir_info.get("editable") is True
        installed = Path(str(distribution.locate_file(PACKAGE_IN_CHECKOUT[-1])))
        if editable and source is not None and package.is_relative_to(source):
            return _checkout_head(source)
        if not editable and installed.resolve() == package:
            vcs_info = info.get("vcs_info")
            commit = vcs_info.get("commit_id") if isinstance(vcs_info, dict) else None
            if isinstance(commit, str) and commit:
                return commit
            return "unknown" if source is None else _checkout_head(source)
    checkout = package.parents[len(PACKAGE_IN_CHECKOUT) - 1]
    return _checkout_head(checkout, package)


def git_commit() -> str:
    """The source commit (:func:`source_commit`), as archives record it."""
    return source_commit()


def versions() -> dict[str, str]:
    """Python's and the packages' versions."""
    found = {"python": platform.python_version()}
    for package in PACKAGES:
        try:
            found[package] = importlib_metadata.version(package)
        except importlib_metadata.PackageNotFoundError:
            found[package] = "unknown"
    return found


def inputs_record(
    simulation: Simulation,
    sphere: Sphere | None = None,
    plate: Plate | None = None,
    *,
    label: str | None = None,
    scene: Mapping[Parameter, float] | None = None,
    **extra: object,
) -> dict[str, Any]:
    """Every input of a run, in user units, and where the code came from (provenance.inputs:
    the format; ``run --inputs`` reads it back; ``plugins``: provenance.code).
    ``scene`` gives values [SI] by declaration (impact speed and obliquity of one
    scene); ``extra`` adds keys as they are (a sweep's grid as typed). Without a sphere
    and plate (a study's runs, whose scenes are stored beside them): the model and
    provenance only."""
    record: dict[str, Any] = {"format": inputs.FORMAT}
    if label is not None:
        record["label"] = label
    for declared, value in (scene or {}).items():
        key, number = inputs.quantity(declared, value)
        record[key] = number
    record.update(extra)
    if sphere is not None:
        record["sphere"] = inputs.sphere_record(sphere)
    if plate is not None:
        record["plate"] = plate_to_dict(plate, registry=simulation.registry)
    record["model"] = inputs.model_record(simulation)
    record["versions"] = versions()
    record["source_commit"] = source_commit()
    record["plugins"] = plugins_record(simulation)
    return record


class RunMetadata:
    """A run's variant, model, versions, host and times."""

    def __init__(self, variant: Variant, simulation: Simulation) -> None:
        self.variant = variant
        self.model = simulation.describe()
        self.plugins = plugins_record(simulation)
        self.state_names = simulation.model.failure.state_names
        self.state_units = simulation.model.failure.state_units
        self.start = dt.datetime.now(dt.UTC)
        self._clock = time.perf_counter()
        self.end = self.start
        self.wall_time = 0.0

    def finish(self) -> None:
        self.end = dt.datetime.now(dt.UTC)
        self.wall_time = time.perf_counter() - self._clock

    def as_attributes(self) -> dict[str, object]:
        return {
            "variant": self.variant.to_json(),
            "model": json.dumps(self.model, sort_keys=True),
            "versions": json.dumps(versions(), sort_keys=True),
            "git_commit": git_commit(),
            "plugins": json.dumps(self.plugins, sort_keys=True),
            "host": socket.gethostname(),
            "start_time": self.start.isoformat(),
            "end_time": self.end.isoformat(),
            "wall_time_s": self.wall_time,
            "failure_state_units": json.dumps(
                dict(zip(self.state_names, self.state_units, strict=False))
            ),
        }
