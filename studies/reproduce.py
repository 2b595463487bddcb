"""Every figure family of the report in one archive, with one figure per family, and the
outcome maps and limit curves of the five plates.

python studies/reproduce.py [--out DIR] [--dpi DPI] [--format png|svg|pdf]
(what `plateimpact reproduce` runs)
"""

from __future__ import annotations

import argparse
import time
from pathlib import Path

import numpy as np

import plateimpact as pi
from plateimpact import limits, plotting, presets
from plateimpact.cli.common import dots_per_inch

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
#: The maps' grid: 100 speeds over 50-2000 m/s, obliquities 0-84 deg by 2 (the five
#: plates found together in about 5 s; `plateimpact map` draws finer ones).
MAP_SPEEDS, MAP_SAMPLES = (50.0, 2000.0), 100
MAP_OBLIQUITIES = np.radians(np.arange(0.0, 85.0, 2.0))


def outcome_maps(
    out: Path, archive: Path, resume: bool = False, dpi: float = plotting.DPI, suffix: str = "png"
) -> tuple[list[limits.OutcomeMap], list[Path]]:
    """The outcome maps of the five plates (default sphere, plugging, dopri5), stored in
    ``archive`` as ``limits/map_PLATE`` (with ``resume``, read back if there), and drawn:
    ``outcome_maps.<suffix>`` and ``limit_curves.<suffix>``."""
    from plateimpact.limits.figures import plot_limit_curves, plot_outcome_map  # noqa: PLC0415

    names = [f"map_{plate.replace('/', '_')}" for plate in presets.PLATES]
    stored = set(limits.stored_limits(archive)) if resume and archive.exists() else set()
    kept = [limits.read_limits(archive, name) for name in names if name in stored]
    found = [m for m in kept if isinstance(m, limits.OutcomeMap)]
    if len(found) < len(names):
        found = limits.outcome_maps(
            pi.Simulation.from_names(), presets.DEFAULT_SPHERE,
            [presets.plate(plate) for plate in presets.PLATES], MAP_SPEEDS, MAP_SAMPLES,
            MAP_OBLIQUITIES,
        )  # fmt: skip
        for name, drawn in zip(names, found, strict=True):
            if name not in stored:  # a resumed archive keeps the maps it has
                limits.archive_limits(archive, name, drawn)
    maps = list(zip(presets.PLATES, found, strict=True))
    paths = [out / f"outcome_maps.{suffix}", out / f"limit_curves.{suffix}"]
    plotting.save(plot_outcome_map(maps), str(paths[0]), dpi=dpi)
    plotting.save(plot_limit_curves(maps), str(paths[1]), dpi=dpi)
    return found, paths


def reproduce(
    out: Path,
    progress: bool | None = None,
    resume: bool = False,
    dpi: float = plotting.DPI,
    suffix: str = "png",
) -> tuple[Path, list[Path]]:
    """Run every family into ``out/report.h5`` and draw its figures (``suffix``: png, svg
    or pdf; ``dpi`` [dots per inch] for PNG). An existing archive is appended to (its
    earlier runs kept; the new ones get a ``.2``, ``.3`` suffix), or with ``resume`` its
    finished runs are read back and only the missing ones run."""
    out.mkdir(parents=True, exist_ok=True)
    archive = out / ARCHIVE_NAME
    drawing = {"resume": resume, "dpi": dpi, "suffix": suffix}
    figures = [run_and_plot(f.study(), out, archive, progress, **drawing) for f in FAMILIES]
    craters = fig35_37_craters_60deg.study()
    figures.append(run_and_plot(craters, out, archive, progress, craters=True, **drawing))
    figures += outcome_maps(out, archive, **drawing)[1]
    return archive, figures


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--out", default="report", help="output directory (created)")
    parser.add_argument("--resume", action="store_true", help="run only the missing runs")
    parser.add_argument("--dpi", type=dots_per_inch, default=plotting.DPI, help="PNG resolution")
    parser.add_argument("--format", choices=("png", "svg", "pdf"), default="png")
    args = parser.parse_args()
    start = time.perf_counter()
    archive, figures = reproduce(
        Path(args.out), resume=args.resume, dpi=args.dpi, suffix=args.format
    )
    print(f"archive: {archive}")
    for figure in figures:
        print(f"figure:  {figure}")
    print(f"({time.perf_counter() - start:.1f} s)")


if __name__ == "__main__":
    main()
