"""plateimpact's wall-clock limits scaled by ``PLATEIMPACT_TEST_TIME_SCALE``.

``PLATEIMPACT_TEST_TIME_SCALE=0.01 python -m pytest`` runs the suite with every time limit
the package has by default multiplied by 0.01: proof that no test passes only because a
clock was generous. tests/conftest.py scales its own process and puts this directory on
PYTHONPATH, so that every Python process the tests start imports this file at start-up
(``sitecustomize``) and scales its limits the same way, each when its module is loaded.

The limits (docs/robustness.md, "work bounds"): an archive's lock wait (``WAIT``, 300 s),
the progress bar's delay (``DELAY``, 2 s), git's timeout (``GIT_TIMEOUT``, 60 s) and the
integrators' ``max_seconds`` (None by default, no limit: nothing to scale; a finite default would
need scaling here, so it stops the run).
"""

from __future__ import annotations

import importlib.abc
import importlib.machinery
import importlib.util
import math
import os
import sys
from collections.abc import Callable, Sequence
from types import ModuleType

#: The factor, 1 unless the environment says otherwise.
SCALE = float(os.environ.get("PLATEIMPACT_TEST_TIME_SCALE", "1"))


def _archive(module: ModuleType, scale: float) -> None:
    module.WAIT *= scale
    module.Archive.__init__.__kwdefaults__["wait"] = module.WAIT


def _progress(module: ModuleType, scale: float) -> None:
    module.DELAY *= scale


def _provenance(module: ModuleType, scale: float) -> None:
    module.GIT_TIMEOUT *= scale


def _integrator(module: ModuleType, scale: float) -> None:
    defaults = (module.MAX_SECONDS.default, module.Integrator.max_seconds)
    if any(default is not None for default in defaults):
        raise RuntimeError(f"max_seconds defaults {defaults}: scale them in {__file__}")


#: What to scale in each module, once it is loaded.
LIMITS: dict[str, Callable[[ModuleType, float], None]] = {
    "plateimpact.storage.archive": _archive,
    "plateimpact.run.progress": _progress,
    "plateimpact.provenance.metadata": _provenance,
    "plateimpact.solve.integrator": _integrator,
}


class _ScaleOnLoad(importlib.abc.MetaPathFinder):
    """Finds the modules of LIMITS as the other finders do, then scales each one's limits
    as soon as it has been executed."""

    def __init__(self, scale: float) -> None:
        self.scale = scale

    def find_spec(
        self, name: str, path: Sequence[str] | None, target: ModuleType | None = None
    ) -> importlib.machinery.ModuleSpec | None:
        if name not in LIMITS:
            return None
        for finder in sys.meta_path:
            if finder is self or not hasattr(finder, "find_spec"):
                continue
            spec = finder.find_spec(name, path, target)
            if spec is not None and spec.loader is not None:
                break
        else:
            return None
        execute, scale = spec.loader.exec_module, self.scale

        def exec_module(module: ModuleType) -> None:
            execute(module)
            LIMITS[name](module, scale)

        spec.loader.exec_module = exec_module  # type: ignore[method-assign]
        return spec


def install(scale: float = SCALE) -> None:
    """Scale the limits by ``scale``: now in the modules already loaded, on loading in
    the others. Nothing at all when ``scale`` is 1."""
    if scale == 1.0 or getattr(sys, "_plateimpact_time_scaled", False):
        return  # once a process: conftest and start-up may both ask
    if not (math.isfinite(scale) and scale > 0.0):
        raise ValueError(f"PLATEIMPACT_TEST_TIME_SCALE must be a number > 0, got {scale}")
    sys._plateimpact_time_scaled = True  # type: ignore[attr-defined]
    for name, scaled in LIMITS.items():
        if name in sys.modules:
            scaled(sys.modules[name], scale)
    sys.meta_path.insert(0, _ScaleOnLoad(scale))


if __name__ == "sitecustomize":  # a process the tests started
    install()
