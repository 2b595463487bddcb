"""What an archive records about a run besides its numbers (docs/archive.md)."""

from __future__ import annotations

import datetime as dt
import json
import platform
import socket
import subprocess
import time
from importlib import metadata as importlib_metadata
from pathlib import Path

from ..simulation import Simulation
from ..variant import Variant

PACKAGES = ("plateimpact", "numpy", "scipy", "attrs", "pluggy", "h5py")


def git_commit() -> str:
    """The git commit of the package's source tree, if it is a checkout ("unknown" if not)."""
    here = Path(__file__).resolve().parent
    try:
        out = subprocess.run(
            ["git", "-C", str(here), "rev-parse", "HEAD"],
            capture_output=True,
            text=True,
            timeout=5,
            check=True,
        )
        return out.stdout.strip()
    except (OSError, subprocess.SubprocessError):
        return "unknown"


def versions() -> dict[str, str]:
    """Python's and the packages' versions."""
    found = {"python": platform.python_version()}
    for package in PACKAGES:
        try:
            found[package] = importlib_metadata.version(package)
        except importlib_metadata.PackageNotFoundError:
            found[package] = "unknown"
    return found


class RunMetadata:
    """A run's variant, model, versions, host and times."""

    def __init__(self, variant: Variant, simulation: Simulation) -> None:
        self.variant = variant
        self.model = simulation.describe()
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
            "host": socket.gethostname(),
            "start_time": self.start.isoformat(),
            "end_time": self.end.isoformat(),
            "wall_time_s": self.wall_time,
            "failure_state_units": json.dumps(
                dict(zip(self.state_names, self.state_units, strict=False))
            ),
        }
