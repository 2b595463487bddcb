"""Every figure family of the report in one archive, with one figure per family, and the
outcome maps and limit curves of the five plates.

python studies/reproduce.py [--out DIR] [--dpi DPI] [--format png|svg|pdf] [--quick]
(what `plateimpact reproduce` runs)

``--quick`` is a smoke test of the whole job: every study, variant and setting, the
stored maps and the experiment part, through the same code, on a few of their scenes
(:func:`quick_study`, :data:`QUICK_MAP_SAMPLES`, the experiment's quick mode), into its
own archive: a few seconds instead of about 25.
"""

from __future__ import annotations

import argparse
import time
from pathlib import Path

import numpy as np

import plateimpact as pi
from plateimpact import limits, presets
from plateimpact.cli.common import dots_per_inch
from plateimpact.figures import saving
from plateimpact.provenance.code import limits_record, plugins_record
from plateimpact.study.reruns import check_code

try:
    from . import (
        fig11_17_6061t6_9_53mm,
        fig18_24_2024t3_6_35mm,
        fig25_31_2024t3_3_18mm,
        fig32_34_2024t3_1_27mm,
        fig35_37_craters_60deg,
        fig38_44_sae1010_1_47mm,
    )
    from ._family import run_and_plot, tagged
    from .experiment import experiment
except ImportError:  # run as a script
    import fig11_17_6061t6_9_53mm
    import fig18_24_2024t3_6_35mm
    import fig25_31_2024t3_3_18mm
    import fig32_34_2024t3_1_27mm
    import fig35_37_craters_60deg
    import fig38_44_sae1010_1_47mm
    from _family import run_and_plot, tagged
    from experiment import experiment

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
#: --quick: each family at 6 of its 146 speeds (50 to 1500 m/s by 290; every obliquity,
#: plate and variant kept), the maps at 8 speeds and 4 obliquities (0 to 84 deg by 28).
QUICK_SPEEDS = np.linspace(50.0, 1500.0, 6)
QUICK_MAP_SAMPLES = 8
QUICK_MAP_OBLIQUITIES = np.radians(np.arange(0.0, 85.0, 28.0))


def quick_study(study: pi.Study) -> pi.Study:
    """``study`` on its scenes at :data:`QUICK_SPEEDS` only: the same name, plates,
    obliquities, variants and settings (a study with none of those speeds is kept whole:
    the crater sections' five)."""
    keep = np.flatnonzero(np.isin(study.scenes.impact_speed, QUICK_SPEEDS))
    if keep.size == 0:
        return study
    labels = [study.plate_labels[k] for k in keep]
    return pi.Study(study.name, study.scenes.take(keep), study.variants, labels, study.description)


def map_names(tag: str | None = None) -> list[str]:
    """The names the five plates' maps are stored under: ``map_PLATE`` (``@TAG``)."""
    marker = "" if tag is None else f"@{tag}"
    return [f"map_{plate.replace('/', '_')}{marker}" for plate in presets.PLATES]


def kept_maps(archive: Path, names: list[str]) -> set[str]:
    """Those of ``names`` stored in ``archive``, which a resume keeps, each checked to
    have been found by the code the maps would run now (StaleRunError otherwise)."""
    if not archive.exists():
        return set()
    stored = set(limits.stored_limits(archive)) & set(names)
    current = {**plugins_record(pi.Simulation.from_names()), "limits": limits_record()}
    for name in sorted(stored):
        recorded = pi.Archive(archive).record(name).attributes.get("plugins")
        check_code(f"archive {archive}: limits/{name}", recorded, current)
    return stored


def outcome_maps(
    out: Path,
    archive: Path,
    resume: bool = False,
    overwrite: bool = False,
    tag: str | None = None,
    dpi: float = saving.DPI,
    suffix: str = "png",
    quick: bool = False,
) -> tuple[list[limits.OutcomeMap], list[Path]]:
    """The outcome maps of the five plates (default sphere, plugging, dopri5), stored in
    ``archive`` as ``limits/map_PLATE`` (or ``map_PLATE@TAG``; with ``resume``, read back
    if there; with ``overwrite``, replaced), and drawn: ``outcome_maps.<suffix>`` and
    ``limit_curves.<suffix>`` (at ``dpi`` [dots per inch] if a raster); ``quick``: on
    the small grid of --quick."""
    from plateimpact.figures.limits_and_maps import plot_limit_curves, plot_outcome_map  # noqa: PLC0415

    names = map_names(tag)
    stored = kept_maps(archive, names) if resume else set()
    kept = [limits.read_limits(archive, name) for name in names if name in stored]
    found = [m for m in kept if isinstance(m, limits.OutcomeMap)]
    if len(found) < len(names):
        samples, rows = (QUICK_MAP_SAMPLES, QUICK_MAP_OBLIQUITIES) if quick else (
            MAP_SAMPLES, MAP_OBLIQUITIES
        )  # fmt: skip
        found = limits.outcome_maps(
            pi.Simulation.from_names(), presets.DEFAULT_SPHERE,
            [presets.plate(plate) for plate in presets.PLATES], MAP_SPEEDS, samples, rows,
        )  # fmt: skip
        for name, drawn in zip(names, found, strict=True):
            if name not in stored:  # a resumed archive keeps the maps it has
                limits.archive_limits(archive, name, drawn, overwrite=overwrite)
    maps = list(zip(presets.PLATES, found, strict=True))
    paths = [out / f"outcome_maps.{suffix}", out / f"limit_curves.{suffix}"]
    saving.save(plot_outcome_map(maps), str(paths[0]), dpi=dpi)
    saving.save(plot_limit_curves(maps), str(paths[1]), dpi=dpi)
    return found, paths


def reproduce(
    out: Path,
    progress: bool | None = None,
    resume: bool = False,
    overwrite: bool = False,
    tag: str | None = None,
    dpi: float = saving.DPI,
    suffix: str = "png",
    quick: bool = False,
) -> tuple[Path, list[Path]]:
    """Run every family into ``out/report.h5`` and draw its figures (``suffix``: png, svg
    or pdf; ``dpi`` [dots per inch] for PNG). Runs already in the archive are refused
    before anything runs, unless ``resume`` (read them back, run only the missing ones),
    ``overwrite`` (replace them) or ``tag`` (store the new runs as ``VARIANT@TAG``, the
    maps as ``map_PLATE@TAG``). A run or map ``resume`` would keep that other code
    computed (a plug-in or the core changed since) is refused before anything runs
    (``StaleRunError``). ``quick``: the same job on small grids (the module's
    description); its archive holds other scenes, so give it its own ``out``."""
    out.mkdir(parents=True, exist_ok=True)
    archive = out / ARCHIVE_NAME
    shrink = quick_study if quick else (lambda study: study)
    studies = [shrink(f.study()) for f in FAMILIES]
    craters = shrink(fig35_37_craters_60deg.study())
    for study in [*studies, craters]:  # a run that is there is refused before any runs
        names = tagged(study, tag)
        study.check_archive(archive, resume=resume, overwrite=overwrite, run_names=names)
    if resume:  # and so is a stored map that other code found
        kept_maps(archive, map_names(tag))
    rerun = {"resume": resume, "overwrite": overwrite, "tag": tag}
    drawing = {"dpi": dpi, "suffix": suffix}
    figures = [run_and_plot(s, out, archive, progress, **rerun, **drawing) for s in studies]
    figures.append(run_and_plot(craters, out, archive, progress, craters=True, **rerun, **drawing))
    figures += outcome_maps(out, archive, **rerun, **drawing, quick=quick)[1]
    figures += experiment(out, dpi, suffix, resume, quick)  # validate, V50, P* fit on shots
    return archive, figures


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--out", default="report", help="output directory (created)")
    rerun = parser.add_mutually_exclusive_group()
    rerun.add_argument("--resume", action="store_true", help="run only the missing runs")
    rerun.add_argument("--overwrite", action="store_true", help="replace the runs there")
    rerun.add_argument("--as", dest="tag", metavar="TAG", help="store new runs as VARIANT@TAG")
    parser.add_argument("--dpi", type=dots_per_inch, default=saving.DPI, help="PNG resolution")
    parser.add_argument("--format", choices=("png", "svg", "pdf"), default="png")
    parser.add_argument("--quick", action="store_true", help="small grids: a smoke test")
    args = parser.parse_args()
    start = time.perf_counter()
    archive, figures = reproduce(
        Path(args.out), None, args.resume, args.overwrite, args.tag, args.dpi, args.format,
        quick=args.quick,
    )  # fmt: skip
    print(f"archive: {archive}")
    for figure in figures:
        print(f"figure:  {figure}")
    print(f"({time.perf_counter() - start:.1f} s)")


if __name__ == "__main__":
    main()
