"""Two snapshots of benchmarks/snapshot.py, group by group: IDENTICAL, or what differs.

Run:  python benchmarks/compare_snapshots.py before.npz after.npz
"""

from __future__ import annotations

import sys

import numpy as np


def main() -> None:
    before, after = np.load(sys.argv[1]), np.load(sys.argv[2])
    differences: dict[str, list[str]] = {}
    for key in before.files:
        group = key.split("/")[0]
        if key not in after.files:
            differences.setdefault(group, []).append(f"{key}: missing")
            continue
        x, y = before[key], after[key]
        if x.shape != y.shape:
            differences.setdefault(group, []).append(f"{key}: shape {x.shape} -> {y.shape}")
        elif not np.array_equal(x, y, equal_nan=x.dtype.kind == "f"):
            if x.dtype.kind == "f":
                both = np.isfinite(x) & np.isfinite(y)
                gained = int(np.sum(np.isnan(x) & ~np.isnan(y)))
                lost = int(np.sum(~np.isnan(x) & np.isnan(y)))
                largest = np.max(np.abs(x - y)[both], initial=0.0)
                text = f"largest change {largest:.3g}, NaN -> value {gained}, value -> NaN {lost}"
            else:
                text = f"{int(np.sum(x != y))} entries differ"
            differences.setdefault(group, []).append(f"{key}: {text}")
    for group in dict.fromkeys(k.split("/")[0] for k in before.files):
        print(f"{group}: {'IDENTICAL' if group not in differences else 'differs'}")
        for line in differences.get(group, []):
            print(f"    {line}")


if __name__ == "__main__":
    main()
