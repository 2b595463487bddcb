"""Every result, statistic and trajectory sample of a fixed set of runs, to an .npz file:
compare two checkouts bit for bit with benchmarks/compare_snapshots.py.

Runs 2,000 seeded benchmark scenes through dopri5 in seven configurations (default,
hinge, variable P*, intact, rtol 1e-10, without branch landing, fixed step), trajectories
of 50 of them (plugging and hinge), 100 through segment and 25 through solve_ivp. It uses
only API that older checkouts have too, so it can run against one:

    git worktree add ../before <commit>
    PYTHONPATH=../before/framework:../before/plugins python benchmarks/snapshot.py before.npz
    python benchmarks/snapshot.py after.npz
    python benchmarks/compare_snapshots.py before.npz after.npz
"""

from __future__ import annotations

import sys

import numpy as np
from scenes import benchmark_batch

import plateimpact as pi

DOPRI5 = {
    "dopri5": {},
    "dopri5_hinge": {"failure": "hinge"},
    "dopri5_variable_pstar": {"failure": "variable-pstar"},
    "dopri5_intact": {"failure": "intact"},
    "dopri5_rtol1e-10": {"integrator_settings": {"rtol": 1e-10}},
    "dopri5_straddling": {"integrator_settings": {"branch_landing": False}},
    "dopri5_fixed_step": {"integrator_settings": {"fixed_step": 0.05}},
}
STATS = ("steps", "force_evaluations", "accepted_steps", "rejected_steps")


def trajectory_columns(result: pi.BatchResult) -> tuple[dict[str, np.ndarray], np.ndarray]:
    """The recorded samples and counts, from a ragged array or the older dict."""
    trajectory = result.trajectory
    if isinstance(trajectory, dict):  # before the Ragged type
        return trajectory, result.trajectory_counts
    return trajectory.values, trajectory.counts


def main() -> None:
    out: dict[str, np.ndarray] = {}
    batch = benchmark_batch(2000, seed=77)
    for name, options in DOPRI5.items():
        result = pi.Simulation.from_names(**options).run_batch(batch)
        out.update({f"{name}/{k}": v for k, v in result.columns.items()})
        out[f"{name}/stats"] = np.array([result.stats.get(s, -1) for s in STATS])
    paths = batch.take(np.arange(0, 2000, 40))
    for name, options in {"paths": {}, "paths_hinge": {"failure": "hinge"}}.items():
        result = pi.Simulation.from_names(**options).run_batch(paths, record_trajectory=True)
        samples, counts = trajectory_columns(result)
        out.update({f"{name}/trajectory/{k}": v for k, v in samples.items()})
        out[f"{name}/counts"] = counts
        out.update({f"{name}/{k}": v for k, v in result.columns.items()})
    segment = batch.take(np.arange(0, 2000, 20))
    for name, options, scenes in (
        ("segment", {"integrator": "segment"}, segment),
        ("solve_ivp", {"integrator": "solve_ivp"}, segment.take(np.arange(0, 100, 4))),
    ):
        result = pi.Simulation.from_names(**options).run_batch(scenes)
        out.update({f"{name}/{k}": v for k, v in result.columns.items()})
    np.savez(sys.argv[1], **out)
    print(f"wrote {len(out)} arrays to {sys.argv[1]} ({pi.__file__})")


if __name__ == "__main__":
    main()
