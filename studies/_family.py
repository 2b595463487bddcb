"""What every figure-family script does when run: run its study into an archive, plot it."""

from __future__ import annotations

import argparse
from pathlib import Path

import plateimpact as pi
from plateimpact.cli.common import dots_per_inch
from plateimpact.figures import exit_curves, saving, study_paths

#: Impact speeds of the figure families [m/s]: the report's figures span 0–1.5 km/s.
SPEEDS = [50.0 + 10.0 * k for k in range(146)]


def tagged(study: pi.Study, tag: str | None) -> dict[str, str] | None:
    """The run names of ``study``'s variants stored ``--as TAG``: ``VARIANT@TAG``."""
    return None if tag is None else {v.name: f"{v.name}@{tag}" for v in study.variants}


def run_and_plot(
    study: pi.Study,
    out: Path,
    archive: Path,
    progress: bool | None = None,
    craters: bool = False,
    resume: bool = False,
    overwrite: bool = False,
    tag: str | None = None,
    dpi: float = saving.DPI,
    suffix: str = "png",
) -> Path:
    """Run ``study`` (appending its runs to ``archive``; with ``resume``, only those not
    there yet; with ``overwrite`` replacing them; with ``tag``, as ``VARIANT@TAG``) and
    draw ``out/<study>.<suffix>`` (at ``dpi`` [dots per inch] if a raster): exit
    curves, or with ``craters`` the crater sections (the runs then keep paths and
    craters)."""
    results = study.run(
        archive=archive, progress=progress, craters=craters, resume=resume,
        overwrite=overwrite, run_names=tagged(study, tag),
    )  # fmt: skip
    if craters:
        figure = study_paths.plot_study_paths(results, kind="crater")
    else:
        figure = exit_curves.plot_study(results)
    path = out / f"{study.name}.{suffix}"
    saving.save(figure, str(path), dpi=dpi)
    return path


def main(study: pi.Study, craters: bool = False) -> None:
    parser = argparse.ArgumentParser(description=study.description)
    parser.add_argument("--out", default=".", help="directory for the archive and the figure")
    parser.add_argument("--dpi", type=dots_per_inch, default=saving.DPI, help="PNG resolution")
    parser.add_argument("--format", choices=("png", "svg", "pdf"), default="png")
    args = parser.parse_args()
    out = Path(args.out)
    drawn = run_and_plot(study, out, out / f"{study.name}.h5", craters=craters,
                         dpi=args.dpi, suffix=args.format)  # fmt: skip
    print(f"archive: {out / f'{study.name}.h5'}\nfigure:  {drawn}")
