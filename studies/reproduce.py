"""Every figure family of the report in one archive, with one PNG per family.

python studies/reproduce.py [--out DIR]      (what `plateimpact reproduce` runs)
"""

from __future__ import annotations

import argparse
import time
from pathlib import Path

try:
    from . import (
        fig11_17_6061t6_9_53mm,
        fig18_24_2024t3_6_35mm,
        fig25_31_2024t3_3_18mm,
        fig32_34_2024t3_1_27mm,
        fig35_37_craters_60deg,
        fig38_44_sae1010_1_47mm,
    )
    from ._family import run_and_plot
except ImportError:  # run as a script
    import fig11_17_6061t6_9_53mm
    import fig18_24_2024t3_6_35mm
    import fig25_31_2024t3_3_18mm
    import fig32_34_2024t3_1_27mm
    import fig35_37_craters_60deg
    import fig38_44_sae1010_1_47mm
    from _family import run_and_plot

FAMILIES = (
    fig11_17_6061t6_9_53mm,
    fig18_24_2024t3_6_35mm,
    fig25_31_2024t3_3_18mm,
    fig32_34_2024t3_1_27mm,
    fig38_44_sae1010_1_47mm,
)
ARCHIVE_NAME = "report.h5"


def reproduce(
    out: Path, progress: bool | None = None, resume: bool = False
) -> tuple[Path, list[Path]]:
    """Run every family into ``out/report.h5`` and draw its PNGs. An existing archive is
    appended to (its earlier runs kept; the new ones get a ``.2``, ``.3`` suffix), or with
    ``resume`` its finished runs are read back and only the missing ones run."""
    out.mkdir(parents=True, exist_ok=True)
    archive = out / ARCHIVE_NAME
    figures = [run_and_plot(f.study(), out, archive, progress, resume=resume) for f in FAMILIES]
    craters = fig35_37_craters_60deg.study()
    figures.append(run_and_plot(craters, out, archive, progress, craters=True, resume=resume))
    return archive, figures


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--out", default="report", help="output directory (created)")
    parser.add_argument("--resume", action="store_true", help="run only the missing runs")
    args = parser.parse_args()
    start = time.perf_counter()
    archive, figures = reproduce(Path(args.out), resume=args.resume)
    print(f"archive: {archive}")
    for figure in figures:
        print(f"figure:  {figure}")
    print(f"({time.perf_counter() - start:.1f} s)")


if __name__ == "__main__":
    main()
