"""Appends in constant time (issue 17): 200 runs of 10,000 scenes appended one by one to
one archive; prints the time of each append against the number of runs already there.

    python benchmarks/archive_append.py [--runs 200] [--scenes 10000] [--dir DIR]

The run is computed once and appended under 200 names (what an append costs does not
depend on the numbers in it). Each append writes the run's own data file and replaces
the index (docs/archive.md), so its cost should not grow with the runs before it.
"""

from __future__ import annotations

import argparse
import statistics
import tempfile
import time
from pathlib import Path

import numpy as np

import plateimpact as pi
from plateimpact.provenance.metadata import RunMetadata


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--runs", type=int, default=200)
    parser.add_argument("--scenes", type=int, default=10_000)
    parser.add_argument("--dir", help="where to write the archive (default: a temporary one)")
    args = parser.parse_args()
    obliquities = 10
    speeds = np.linspace(50.0, 1500.0, args.scenes // obliquities)
    study = pi.Study.grid(
        "append", ["2024-T3/3.18"], np.linspace(0.0, 80.0, obliquities), speeds,
        [pi.Variant(f"v{k:03d}") for k in range(args.runs)],
    )  # fmt: skip
    variant = study.variants[0]
    simulation = variant.simulation()
    metadata = RunMetadata(variant, simulation)
    result = simulation.run_batch(study.scenes)
    metadata.finish()
    attributes = metadata.as_attributes()
    constants = simulation.model.plate_constants()
    with tempfile.TemporaryDirectory(dir=args.dir) as directory:
        archive = pi.Archive(Path(directory) / "append.h5")
        seconds = []
        for variant in study.variants:
            start = time.perf_counter()
            archive.append_run(study, variant, result, attributes, constants)
            seconds.append(time.perf_counter() - start)
        index = archive.real.stat().st_size
        data = sum(p.stat().st_size for p in archive.data.iterdir())
        assert len(archive.runs()) == args.runs
    first = statistics.median(seconds[1:11])  # run 1 also writes the study's scenes
    last = statistics.median(seconds[-10:])
    print(f"{args.runs} runs of {study.scenes.size:,} scenes appended one by one")
    print(f"append at run 1 (writes the study too): {seconds[0] * 1e3:8.1f} ms")
    print(f"median of runs 2-11:                    {first * 1e3:8.1f} ms")
    print(f"median of the last 10 runs:             {last * 1e3:8.1f} ms")
    print(f"ratio last / first:                     {last / first:8.2f}")
    print(f"index {index / 1024:.0f} KiB; data files {data / 2**20:.0f} MiB")
    for k in (1, 50, 100, 150, args.runs):
        if k <= len(seconds):
            print(f"  run {k:4d}: {seconds[k - 1] * 1e3:7.1f} ms")


if __name__ == "__main__":
    main()
