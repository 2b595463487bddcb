"""SIMD across scenes, measured (issue 23, item 7): lanes of scenes evaluated and stepped
together, against one scene at a time, in compiled code on one core.

The model: an intact 2024-T3 plate (the preset's Poncelet constants a, b) and the default
sphere; scenes of 300-1500 m/s at 0-80 deg, seeded. Two measurements:

1. the force (drag and lift from P, θ, V; eqs 1-6, 22-24) at one state per scene (drawn
   uniformly from the scene's accepted steps): the package's kernel called per scene, and
   lanes of 4 and 8 scenes evaluated together (benchmarks/simd_kernels.py), fastmath off
   and on;
2. Dormand-Prince 5(4) with the project's error control (rtol 1e-8), each scene run to
   contact lost or rest (no root refinement, no branch landing): one scene at a time, and
   lanes of 4 and 8 scenes with per-lane steps and accept masks, a lane refilled from the
   queue when its scene ends.

Lane and scalar results are checked equal (bit for bit without fastmath, with equal
force-evaluation counts), the outcomes against plateimpact's numpy path. The machine is
shared, so the variants run in turn (scalar, lanes 4, lanes 8, ...), ``--repeats`` rounds;
the table gives each one's median and spread. docs/integrators.md, "SIMD across scenes
(measured)", has the figures and the conclusion.

Run:  pip install plateimpact[fast] && python benchmarks/simd_lanes.py [--scenes 10000]
"""

from __future__ import annotations

import argparse
import os
import platform
import re
import statistics
import sys
import time
import warnings

import numpy as np

import plateimpact as pi
from plateimpact import presets
from plateimpact.model import geometry

try:
    import llvmlite.binding as llvm
    import numba
except ImportError:
    sys.exit("this benchmark needs numba: pip install plateimpact[fast]")

import simd_kernels as kernels  # noqa: E402 (needs numba)

RTOL, REST_FRACTION, MAX_STEPS = 1e-8, 1e-2, 20_000
FORCE_REPEATS = 20  # evaluations of the whole state array per timing
REMARKS = False  # LLVM's vectorization remarks to stderr (--remarks)


def compile_now(function, fastmath: bool, width: int, *example, remarks: bool = False):
    """``function`` compiled now, with LLVM's loop vectorizer forced to ``width`` lanes
    (0: its own choice) and no interleaving, so that a lane loop of ``width`` iterations
    runs as one vector iteration; the vector width it used is checked in the IR. LLVM's
    remarks on the loops it could not vectorize go to stderr only with ``remarks``."""
    llvm.set_option("simd_lanes", f"-force-vector-width={width}")
    llvm.set_option("simd_lanes", f"-force-vector-interleave={1 if width else 0}")
    stderr = os.dup(2)
    if not remarks:  # LLVM writes them to the file descriptor, past sys.stderr
        os.dup2(os.open(os.devnull, os.O_WRONLY), 2)
    try:
        jitted = numba.njit(error_model="numpy", fastmath=fastmath, debug=remarks)(function)
        jitted(*example)
    finally:
        os.dup2(stderr, 2)
        llvm.set_option("simd_lanes", "-force-vector-width=0")
        llvm.set_option("simd_lanes", "-force-vector-interleave=0")
    ir = jitted.inspect_llvm(jitted.signatures[0])
    widths = {int(w) for w in re.findall(r"<(\d+) x double>", ir)}
    if width:
        assert width in widths and max(widths) == width, (function.__name__, width, widths)
    return jitted


def scenes(size: int, seed: int = 23) -> tuple[np.ndarray, np.ndarray]:
    """Impact speeds [m/s] uniform in 300-1500 and obliquities [rad] in 0-80 deg."""
    rng = np.random.default_rng(seed)
    return rng.uniform(300.0, 1500.0, size), np.radians(rng.uniform(0.0, 80.0, size))


def median_spread(values: list[float]) -> str:
    return f"{statistics.median(values):9.3g} ({min(values):.3g}-{max(values):.3g})"


def in_turns(variants: dict, repeats: int) -> dict[str, list[float]]:
    """Each variant's timings [s], the variants run in turn, ``repeats`` rounds."""
    times: dict[str, list[float]] = {name: [] for name in variants}
    for _ in range(repeats):
        for name, run in variants.items():
            start = time.perf_counter()
            run()
            times[name].append(time.perf_counter() - start)
    return times


def measure_forces(states, constants, repeats: int) -> None:
    rs, _, a, b = constants
    pen, obl, speed = (np.ascontiguousarray(row) for row in states)
    n = pen.size
    outputs = {}
    variants = {}
    for fastmath in (False, True):
        for width in (1, 4, 8):
            drag, lift = np.empty(n), np.empty(n)
            if width == 1:
                args = (pen, obl, speed, rs, a, b, drag, lift)
                jitted = compile_now(kernels.scalar_forces, fastmath, 0, *args, remarks=REMARKS)
            else:
                args = (pen, obl, speed, rs, a, b, drag, lift, width, np.empty(width))
                jitted = compile_now(
                    kernels.lane_forces_in_blocks, fastmath, width, *args, remarks=REMARKS
                )
            name = f"{'scalar' if width == 1 else f'lanes of {width}'}, fastmath {fastmath}"
            outputs[name] = (drag, lift)
            variants[name] = lambda f=jitted, a=args: [f(*a) for _ in range(FORCE_REPEATS)]
    exact = outputs["scalar, fastmath False"]
    for name, (drag, lift) in outputs.items():
        scale = np.abs(exact[0]).max()
        worst = max(np.abs(drag - exact[0]).max(), np.abs(lift - exact[1]).max()) / scale
        same = "bit-identical" if worst == 0.0 else f"max difference {worst:.1e} of the largest"
        print(f"  {name}: {same} to the scalar kernel without fastmath")
    times = in_turns(variants, repeats)
    per_state = {k: [t / (FORCE_REPEATS * n) * 1e9 for t in v] for k, v in times.items()}
    print(f"\n1. force evaluation on {n} states, ns per state: median (spread)")
    for fastmath in (False, True):
        base = statistics.median(per_state[f"scalar, fastmath {fastmath}"])
        for width in (1, 4, 8):
            name = f"{'scalar' if width == 1 else f'lanes of {width}'}, fastmath {fastmath}"
            ratio = base / statistics.median(per_state[name])
            print(f"  {name:28s} {median_spread(per_state[name])}  x{ratio:.2f}")


def measure_stepping(speeds, obliquities, constants, repeats: int, sample) -> np.ndarray:
    n = speeds.size
    common = (speeds, obliquities, *constants, RTOL, REST_FRACTION, MAX_STEPS)
    variants, outputs, totals = {}, {}, {}
    for fastmath in (False, True):
        for width in (1, 4, 8):
            out = np.zeros((6, n))
            if width == 1:  # the first run (it compiles) draws the sample, untimed
                args = (*common, out, sample if not fastmath else np.empty((3, 0)))
                jitted = compile_now(kernels.run_scalar, fastmath, 0, *args, remarks=REMARKS)
                args = (*common, out, np.empty((3, 0)))
            else:
                args = (*common, out, width)
                jitted = compile_now(kernels.run_lanes, fastmath, width, *args, remarks=REMARKS)
            name = f"{'scalar' if width == 1 else f'lanes of {width}'}, fastmath {fastmath}"
            totals[name] = jitted(*args)
            outputs[name] = out.copy()
            variants[name] = lambda f=jitted, a=args: f(*a)
    exact = outputs["scalar, fastmath False"]
    ricochets = exact[0] == kernels.RICOCHET
    for name, out in outputs.items():
        if np.array_equal(out, exact):
            verdict = "bit-identical"
        else:  # an embedment ends at a step past the rest speed: its speed not compared
            error = np.abs(out[3] - exact[3])[ricochets] / speeds[ricochets]
            verdict = (
                f"{np.count_nonzero(out[0] != exact[0])} outcomes differ, ricochet exit "
                f"speeds by up to {error.max():.1e} Vs (median {np.median(error):.0e})"
            )
        print(f"  {name}: {verdict}; {totals[name] / n:.1f} force evaluations per scene")
    times = in_turns(variants, repeats)
    print(f"\n2. Dormand-Prince 5(4) over {n} scenes, scenes/s: median (spread)")
    for fastmath in (False, True):
        base = statistics.median(times[f"scalar, fastmath {fastmath}"])
        for width in (1, 4, 8):
            name = f"{'scalar' if width == 1 else f'lanes of {width}'}, fastmath {fastmath}"
            rates = [n / t for t in times[name]]
            ratio = base / statistics.median(times[name])
            print(f"  {name:28s} {median_spread(rates)}  x{ratio:.2f}")
    return exact


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--scenes", type=int, default=10_000)
    parser.add_argument("--repeats", type=int, default=5)
    parser.add_argument(
        "--remarks", action="store_true", help="LLVM's remarks on every loop (slower)"
    )
    args = parser.parse_args()
    if args.remarks:
        llvm.set_option("simd_lanes", "-pass-remarks=loop-vectorize")
    global REMARKS
    REMARKS = args.remarks
    numba.set_num_threads(1)
    # numba's inlining of the lane helpers trips a pedantic internal check; harmless
    warnings.simplefilter("ignore", numba.errors.NumbaIRAssumptionWarning)
    cpu = next(
        (line.split(":", 1)[1].strip() for line in open("/proc/cpuinfo") if "model name" in line),
        platform.processor(),
    )
    print(
        f"{cpu} (LLVM target {llvm.get_host_cpu_name()}); numba {numba.__version__}, "
        f"USING_SVML {numba.config.USING_SVML} (llvmlite SVML-patched: "
        f"{llvm.config.has_svml}); one thread"
    )
    plate, sphere = presets.plate("2024-T3/3.18"), presets.DEFAULT_SPHERE
    plate_constants = dict(plate.constants)
    constants = (sphere.radius, sphere.mass, plate_constants["a"], plate_constants["b"])
    speeds, obliquities = scenes(args.scenes)
    sample = np.zeros((3, args.scenes))
    # numba's own generator draws the sample (compiled code has no np.random.Generator)
    numba.njit(lambda: np.random.seed(23))()  # noqa: NPY002
    print(f"compiling and checking the steppers ({args.scenes} scenes) ...")
    exact = measure_stepping(speeds, obliquities, constants, args.repeats, sample)
    reference = reference_outcomes(speeds, obliquities, plate)
    agree = np.count_nonzero(exact[0] == reference)
    print(f"  outcomes equal to plateimpact's numpy path (intact) on {agree} of {args.scenes}")
    sample[1] = np.abs(sample[1])
    alpha1 = geometry.entry_edge_angle(sample[0], constants[0])
    ring = geometry.in_turnaround_ring(alpha1, sample[1])[: args.scenes // 8 * 8]
    print(
        f"\nthe force's states: one accepted state per scene; {ring.mean():.1%} in the "
        f"turn-around ring, lanes of 4/8 with one: "
        f"{ring.reshape(-1, 4).any(axis=1).mean():.1%}/{ring.reshape(-1, 8).any(axis=1).mean():.1%}"
    )
    measure_forces(sample, constants, args.repeats)


def reference_outcomes(speeds, obliquities, plate) -> np.ndarray:
    """The outcome codes of plateimpact's default simulation of the intact plate."""
    simulation = pi.Simulation.from_names(failure="intact")
    batch = pi.SceneBatch.grid(
        presets.DEFAULT_SPHERE, plate, np.full(speeds.size, 100.0), [0.0]
    ).with_columns(impact_speed=speeds, impact_obliquity=obliquities)
    return simulation.run_batch(batch).outcome


if __name__ == "__main__":
    main()
