from __future__ import annotations

import importlib
import importlib.util
import os
import shutil
import sys
from pathlib import Path

import numpy as np
import pytest

import plateimpact as pi
from plateimpact import presets

#: A third-party plug-in package, usable without installing it (its .dist-info is beside it).
THIRD_PARTY = Path(__file__).resolve().parent / "third_party"
#: PLATEIMPACT_TEST_TIME_SCALE=0.01 python -m pytest: every wall-clock limit the package
#: has by default scaled by 0.01, here and in every Python process the tests start
#: (time_scale/sitecustomize.py, which they import at start-up from PYTHONPATH).
TIME_SCALE = Path(__file__).resolve().parent / "time_scale"


def _scale_time_limits() -> float:
    spec = importlib.util.spec_from_file_location(
        "plateimpact_test_time_scale", TIME_SCALE / "sitecustomize.py"
    )
    assert spec is not None and spec.loader is not None
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    module.install()
    if module.SCALE != 1.0:
        os.environ["PYTHONPATH"] = os.pathsep.join(
            [str(TIME_SCALE), *filter(None, [os.environ.get("PYTHONPATH")])]
        )
        sys.path.append(str(TIME_SCALE))  # for tests that pass sys.path on to children
    return module.SCALE


SCALE = _scale_time_limits()
#: No test starts a detached compile ("auto" runs a pair whose program is not in the cache
#: on the numpy path); tests/test_warming.py tests that start with Popen recorded.
os.environ["PLATEIMPACT_COMPILE"] = "off"


def pytest_report_header() -> str:
    return f"plateimpact time limits scaled by {SCALE:g} (PLATEIMPACT_TEST_TIME_SCALE)"


@pytest.fixture(scope="session", autouse=True)
def compiled_programs() -> None:
    """The built-in models' compiled programs, compiled (or loaded) before any test runs,
    so that every ``engine="auto"`` run in the suite takes the compiled path whatever the
    cache held (no test depends on a background compile's timing). Each xdist worker
    takes the programs in its own order; the programs' locks make each compile once."""
    if importlib.util.find_spec("numba") is None:
        return
    from plateimpact.solve.compiled import warming

    pairs = warming.compiled_pairs(pi.default_registry())
    if os.environ.get("PYTEST_XDIST_WORKER", "gw0")[-1:] in "13579":
        pairs.reverse()
    warming.compile_pairs(pairs)


@pytest.fixture(scope="session")
def sphere() -> pi.Sphere:
    return presets.DEFAULT_SPHERE


@pytest.fixture(scope="session")
def radius(sphere: pi.Sphere) -> float:
    return sphere.radius


@pytest.fixture
def with_third_party(monkeypatch):
    """The package in tests/third_party installed, as far as entry points can tell (its
    .dist-info is beside it), for this test only."""
    monkeypatch.syspath_prepend(str(THIRD_PARTY))
    importlib.invalidate_caches()
    pi.default_registry.cache_clear()
    yield
    pi.default_registry.cache_clear()


@pytest.fixture(scope="session")
def docs_plugins() -> dict[str, object]:
    """The Python blocks of docs/plugins.md, run in order in one namespace (the third-party
    package importable, as the page assumes it installed)."""
    import re
    import sys

    text = (Path(__file__).resolve().parents[1] / "docs" / "plugins.md").read_text()
    namespace: dict[str, object] = {"__name__": "docs_plugins"}
    sys.path.insert(0, str(THIRD_PARTY))
    importlib.invalidate_caches()
    try:
        for block in re.findall(r"```python\n(.*?)```", text, re.S):
            exec(compile(block, "docs/plugins.md", "exec"), namespace)
    finally:
        sys.path.remove(str(THIRD_PARTY))
        pi.default_registry.cache_clear()
    return namespace


@pytest.fixture(scope="session")
def docs_registry(docs_plugins: dict[str, object]) -> pi.PluginRegistry:
    """The installed plug-ins and the third-party package whose modules docs/plugins.md
    shows (its failure model ``brittle`` and integrator ``rk4`` among them)."""
    sys.path.insert(0, str(THIRD_PARTY))
    importlib.invalidate_caches()
    try:
        return pi.load_registry()
    finally:
        sys.path.remove(str(THIRD_PARTY))


#: Every built-in integrator and the one written in docs/plugins.md: the event tests
#: run on each (through ``docs_registry``).
EVERY_INTEGRATOR = ["dopri5", "segment", "solve_ivp", "rk4"]

#: Settings of the fixed-step integrators for claims that hold at any step (events located
#: on the dense output, exact zeros, bitwise equalities): steps 10 and 5 times their
#: defaults; the adaptive ones keep theirs (``COARSE_STEPS.get(name, {})``).
COARSE_STEPS = {"segment": {"step": 1e-2}, "rk4": {"step": 5e-2}}


def sweep(
    plate: str,
    speeds: np.ndarray,
    obliquity_deg: float,
    *,
    integrator: str = "dopri5",
    step: float = 2e-3,
    failure: str = "plugging",
    record_trajectory: bool = False,
) -> pi.BatchResult:
    """Results of one plate preset at one obliquity over ``speeds`` [m/s]; ``step`` is
    used by the segment integrator only."""
    settings = {"step": step} if integrator == "segment" else {}
    simulation = pi.Simulation.from_names(
        failure=failure, integrator=integrator, integrator_settings=settings
    )
    batch = pi.SceneBatch.grid(
        presets.DEFAULT_SPHERE,
        presets.plate(plate),
        speeds,
        [np.radians(obliquity_deg)],
    )
    return simulation.run_batch(batch, record_trajectory=record_trajectory)


# Hypothesis profiles: "ci" (the default: few examples, derandomized so CI is
# reproducible) and "stress" (HYPOTHESIS_PROFILE=stress python -m pytest
# tests/test_properties.py: many random examples). No deadline: a test's outcome never
# depends on how fast the machine is.
try:
    from hypothesis import HealthCheck, settings

    settings.register_profile(
        "ci",
        max_examples=12,
        deadline=None,
        derandomize=True,
        suppress_health_check=[HealthCheck.too_slow],
    )
    settings.register_profile(
        "stress", max_examples=100, deadline=None, suppress_health_check=[HealthCheck.too_slow]
    )
    settings.load_profile(os.environ.get("HYPOTHESIS_PROFILE", "ci"))
except ImportError:  # hypothesis is a test extra
    pass
try:
    # Hypothesis (6.131 on) also draws numbers it finds in the local modules imported so
    # far, so a derandomized test's examples would depend on which tests ran before it
    # in its process: under pytest-xdist, on the scheduling and so on the machine's load
    # (the intact/segment property test drew scenes 8x as long in the whole suite as
    # alone). The suite keeps that pool empty: a test's examples are its own.
    from hypothesis.internal.conjecture import providers as _providers

    _providers._get_local_constants = lambda: _providers._local_constants
except (ImportError, AttributeError):  # an older Hypothesis has no such pool
    pass


@pytest.fixture(scope="session")
def quick_report(tmp_path_factory: pytest.TempPathFactory) -> Path:
    """The output directory of ``plateimpact reproduce --quick --dpi 50``, made once per
    session: the archive ``report.h5`` (every study, variant and setting kind of the
    report, the stored outcome maps) and the figures and P* table. Read it only: copy
    it (``shutil.copytree``) to change it.

    Under pytest-xdist it is made once for all workers (about 15 s of CPU): the first
    worker to need it makes it, under a lock, in the session's directory they share;
    each then reads its own copy, whose archive lock file it rewrites (an ``upgrade``
    that refuses the current format, as a writer does) so that the file names this
    process, as it would had this process written the report."""
    import contextlib
    import fcntl
    import io

    from plateimpact.cli import main

    def quietly(argv: list[str]) -> tuple[int, str]:
        printed, errors = io.StringIO(), io.StringIO()
        with contextlib.redirect_stdout(printed), contextlib.redirect_stderr(errors):
            code = main(argv)
        return code, errors.getvalue()

    out = tmp_path_factory.mktemp("quick") / "report"
    if os.environ.get("PYTEST_XDIST_WORKER") is None:  # one process: made here
        code, errors = quietly(["reproduce", "--quick", "--out", str(out), "--dpi", "50"])
        assert code == 0, errors
        return out
    shared = tmp_path_factory.getbasetemp().parent / "quick_report"  # this session's
    shared.mkdir(exist_ok=True)
    made, master = shared / "made", shared / "report"
    with open(shared / "lock", "w") as lock:
        fcntl.flock(lock, fcntl.LOCK_EX)  # let go when the file closes
        if not made.exists():
            shutil.rmtree(master, ignore_errors=True)  # another worker's, failed half-way
            code, errors = quietly(["reproduce", "--quick", "--out", str(master), "--dpi", "50"])
            assert code == 0, errors
            made.touch()
    shutil.copytree(master, out)
    code, errors = quietly(["upgrade", str(out / "report.h5")])
    assert code == 2 and "nothing to upgrade" in errors, errors
    return out


@pytest.fixture
def chunks(monkeypatch):
    """The sizes of the chunks of scenes run (``run.simulation.run_chunk``, where the one
    dispatch of runs and studies looks it up), in order."""
    from plateimpact.run import simulation  # noqa: PLC0415

    sizes: list[int] = []
    real = simulation.run_chunk

    def counted(sim, bound, *args):
        sizes.append(bound.size)
        return real(sim, bound, *args)

    monkeypatch.setattr(simulation, "run_chunk", counted)
    return sizes
