"""Wall time of a 10,000-scene sweep with the default integrator on each path, and what
each skip saves.

  * the sweep on the compiled path (one thread, then one per core), on the numpy path,
    and through scipy's DOP853 (solve_ivp, one run) at the default rtol, on the same
    scenes; the compiled path's results against the numpy path's; on every core against
    the numpy path's process pool too;
  * the numpy sweep: minimum of 5 runs after a warm-up, in this process (the machine is
    shared: single runs vary by ±20%);
  * the same sweep spread over a 2-process pool (one chunk per core): warm, and including
    the pool's start;
  * trajectories: the same sweep recording them (they are off unless asked for);
  * failure terms: one force evaluation on 10,000 states of which a fifth have failed,
    computing the failure terms only for those (what the model does) and for every scene;
  * crater sections: the cost per scene of the crater, computed only on request.

Run:  python benchmarks/throughput.py [--scenes 10000]
"""

from __future__ import annotations

import argparse
import os
import time
from concurrent.futures import ProcessPoolExecutor

import attrs
import numpy as np
from scenes import benchmark_batch

import plateimpact as pi
from plateimpact.model.crater import crater_section


def best_of(function, repeats=5):
    function()  # warm-up
    times = []
    for _ in range(repeats):
        start = time.perf_counter()
        function()
        times.append(time.perf_counter() - start)
    return min(times)


def compiled_paths(
    batch: pi.SceneBatch, numpy_result: pi.BatchResult, numpy_time: float, pool_time: float
) -> None:
    """The same sweep on the compiled path, on one thread and on every core, against the
    numpy path in one process and (on every core) on its warm process pool."""
    from plateimpact.solve.compiled import engine

    compiled = attrs.evolve(pi.Simulation.from_names(), engine="compiled")
    start = time.perf_counter()
    result = compiled.run_batch(batch)  # compiles, or loads the program from the cache
    print(f"compiled path: first run {time.perf_counter() - start:.2f} s (compile or cache load)")
    speed = batch.columns["impact_speed"]
    worst = np.max(np.abs(result.exit_speed - numpy_result.exit_speed) / speed)
    angle = np.degrees(
        np.max(np.abs(result.columns["exit_obliquity"] - numpy_result.columns["exit_obliquity"]))
    )
    same = np.array_equal(result.outcome, numpy_result.outcome)
    print(
        f"  against the numpy path: outcomes {'equal' if same else 'DIFFER'}, exit speed "
        f"within {worst:.1e} Vs, exit obliquity within {angle:.1e} deg"
    )
    for threads in (1, os.cpu_count() or 1):
        engine.set_threads(threads)
        took = best_of(lambda: compiled.run_batch(batch))
        pool = f", {pool_time / took:.1f}x its {threads}-process pool" if threads > 1 else ""
        print(
            f"  {threads} thread(s): {took:.3f} s ({took / batch.size * 1e6:.1f} us per "
            f"scene), {numpy_time / took:.1f}x the numpy path{pool}"
        )
    engine.set_threads(0)


def scipy_reference(batch: pi.SceneBatch, numpy_result: pi.BatchResult, numpy_time: float) -> None:
    """The same sweep through scipy's DOP853 at the default rtol (one run: it is slow)."""
    rtol = pi.Simulation.from_names().integrator.rtol
    scipy_run = pi.Simulation.from_names(
        integrator="solve_ivp", integrator_settings={"method": "DOP853", "rtol": rtol}
    )
    start = time.perf_counter()
    result = scipy_run.run_batch(batch)
    took = time.perf_counter() - start
    same = np.mean(result.outcome == numpy_result.outcome) * 100
    print(
        f"scipy DOP853 (solve_ivp) at rtol {rtol:g}: {took:.1f} s ({took / batch.size * 1e6:.0f} "
        f"us per scene; {took / numpy_time:.0f}x the numpy path; outcomes equal on {same:.2f}%)"
    )


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--scenes", type=int, default=10_000)
    args = parser.parse_args()
    batch = benchmark_batch(args.scenes, seed=10_000)
    simulation = pi.Simulation.from_names(engine="numpy")
    print(f"integrator: {simulation.integrator.name} {simulation.integrator.settings()}")

    sweep = best_of(lambda: simulation.run_batch(batch))
    result = simulation.run_batch(batch)
    counts = np.bincount(result.outcome, minlength=4)[1:]
    print(
        f"numpy path, sweep of {batch.size} scenes: {sweep:.2f} s wall "
        f"({sweep / batch.size * 1e6:.0f} us per scene; ricochet/embedment/perforation "
        f"{'/'.join(map(str, counts))})"
    )
    workers = os.cpu_count() or 1
    chunk = -(-batch.size // workers)
    start = time.perf_counter()
    with ProcessPoolExecutor(workers) as pool:
        spread = simulation.run_batch(batch, executor=pool, chunk_size=chunk)
        cold = time.perf_counter() - start
        warm = best_of(lambda: simulation.run_batch(batch, executor=pool, chunk_size=chunk))
    assert np.array_equal(spread.exit_speed, result.exit_speed)
    print(
        f"the same sweep on a {workers}-process pool: {warm:.2f} s warm, {cold:.2f} s "
        f"including the pool's start (results bit-identical)"
    )
    compiled_paths(batch, result, sweep, warm)
    scipy_reference(batch, result, sweep)
    per_scene = result.stats["force_evaluations"] / batch.size
    steps = (result.stats["accepted_steps"] + result.stats["rejected_steps"]) / batch.size
    print(
        f"per scene: {per_scene:.0f} force evaluations, {steps:.0f} steps "
        f"({result.stats['rejected_steps'] / batch.size:.0f} rejected)"
    )

    recorded = best_of(lambda: simulation.run_batch(batch, record_trajectory=True), repeats=1)
    print(f"with trajectories recorded: {recorded:.2f} s (+{(recorded / sweep - 1) * 100:.0f}%)")

    model = simulation.model
    bound = model.bind(batch)
    rng = np.random.default_rng(1)
    pen = rng.uniform(0.0, 2.0, batch.size) * bound.core.radius
    obl = rng.uniform(0.0, np.pi / 2, batch.size)
    spd = bound.core.impact_speed * rng.uniform(0.1, 1.0, batch.size)
    state = model.new_failure_state(batch.size)
    some = rng.uniform(size=batch.size) < 0.2
    every = np.ones(batch.size, bool)
    only_failed = best_of(lambda: model.forces(pen, obl, spd, some, state, bound), repeats=20)
    intact_only = best_of(lambda: model.forces(pen, obl, spd, ~every, state, bound), repeats=20)
    all_terms = best_of(lambda: model.forces(pen, obl, spd, every, state, bound), repeats=20)
    print(
        f"force evaluation, 10,000 states: intact {intact_only * 1e3:.2f} ms; 20% failed "
        f"{only_failed * 1e3:.2f} ms; failure terms for every scene {all_terms * 1e3:.2f} ms "
        f"(skipping saves {(1 - only_failed / all_terms) * 100:.0f}%)"
    )

    sample = batch.take(np.arange(50))
    paths = simulation.run_batch(sample, record_trajectory=True)
    radius = sample.radius
    crater = best_of(
        lambda: [crater_section(paths.trajectory_of(i), radius[i]) for i in range(sample.size)],
        repeats=1,
    )
    print(
        f"crater section: {crater / sample.size * 1e3:.1f} ms per scene, computed only on request"
    )


if __name__ == "__main__":
    main()
