"""Compile every program the test suite runs into the cache, before the suite (CI compiles
once, issue 23; `.ci/run`), so that the suite's time is its tests'.

Beyond the built-in pairs (``plateimpact compile``, which `.ci/run` runs first), the suite
compiles two programs no user needs: the third-party package's compiled law (the kernel
docs/plugins.md shows) with the default failure model, for tests/test_docs.py, and the
hinge program's one-scene-at-a-time driver, which tests/test_compiled.py compares the
lanes with. Without this step the suite compiles them itself (about 30 s of CPU).

Run:  python tests/compile_test_programs.py
"""

from __future__ import annotations

import sys
import time
from pathlib import Path

THIRD_PARTY = Path(__file__).resolve().parent / "third_party"


def main() -> int:
    import plateimpact as pi  # noqa: PLC0415
    from plateimpact.solve.compiled import building  # noqa: PLC0415

    sys.path.insert(0, str(THIRD_PARTY))  # as tests/conftest.py's docs_registry
    registry = pi.load_registry()
    start = time.perf_counter()
    docs = pi.Simulation.from_names(resistance="isotropic-poncelet", registry=registry)
    building.build(type(docs.model.resistance), type(docs.model.failure))
    hinge = pi.Simulation.from_names(failure="hinge")
    program = building.build(type(hinge.model.resistance), type(hinge.model.failure))
    program.run_one_at_a_time(0, 0, 1, *building.signature_arguments())
    print(f"test programs compiled or loaded in {time.perf_counter() - start:.1f} s")
    return 0


if __name__ == "__main__":
    sys.exit(main())
