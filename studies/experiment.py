"""The model against (synthetic) experiment: validate, V50 and the variable-P* fit on the
example shot files of studies/data/, the 1.47-mm SAE 1010 plate (what `plateimpact
reproduce` adds to its output, docs/experiment.md).

python studies/experiment.py [--out DIR]

The files are **synthetic** (their headers say how they were made: the model's own
outcomes with stated noise, studies/make_oblique_shots.py and make_v50_shots.py), so
what this shows is that the tools give back what was put in: the variable-P* model
agrees with the shots made from it and the constant-P* model does not; V50 lies near the
model's ballistic limit; the by-obliquity fit gives a P* table near the one the shots
were made from.
"""

from __future__ import annotations

import argparse
import hashlib
import json
import math
import time
from pathlib import Path
from typing import Any

import plateimpact as pi
from plateimpact import limits, presets
from plateimpact.base.errors import PlateImpactError
from plateimpact.base.untrusted import load_json
from plateimpact.figures import saving
from plateimpact.figures.v50_fits import Panel, v50_figure
from plateimpact.figures.validation_panels import validation_figure
from plateimpact.provenance.code import plugins_record
from plateimpact.provenance.metadata import versions
from plateimpact.provenance.source_hash import module_sources, source_sha256
from plateimpact.storage.output import write_text
from plateimpact_plugins.report import fit_pstar_by_obliquity

DATA = Path(__file__).resolve().parent / "data"
PLATE = "SAE1010/1.47"
OBLIQUE = DATA / "oblique_SAE1010_1.47mm_variable_pstar.csv"
GO_NO_GO = DATA / "gonogo_SAE1010_1.47mm.csv"
MODELS = {"constant-pstar": "plugging", "variable-pstar": "variable-pstar"}
#: reproduce --quick: the P* table fitted to the oblique shots at this obliquity only
#: [deg] (the one whose ricochet and perforation ranges both hold enough shots), its
#: boundaries to 5 m/s with no band of 50 m/s missed; the V50 intervals from 100
#: bootstrap resamples instead of 1000.
QUICK_FIT_OBLIQUITY = 45.0
QUICK_FIT_FINDER = {"resolution": 50.0, "tolerance": 5.0}
QUICK_BOOTSTRAP = 100
#: What produced the outputs (code, shot files), beside them: a resume keeps them only
#: while it is what would produce them now.
PROVENANCE = "experiment_provenance.json"


def provenance() -> dict[str, Any]:
    """The code and data the outputs depend on: every module of plateimpact and of the
    studies this one imports (hashed as provenance.code hashes a plug-in), the
    models' plug-ins and core, the package versions, and the shot files' SHA-256."""
    # The tools it reaches as pi.NAME (imported on first use, so not read as imports)
    # are roots beside it.
    tools = [f"plateimpact.{m}" for m in ("calibration", "experiment", "v50", "storage.shots")]
    sources = module_sources((__name__, *tools), ["plateimpact", __name__.partition(".")[0]])
    plugins = {name: plugins_record(pi.Simulation.from_names(failure=failure))
               for name, failure in MODELS.items()}  # fmt: skip
    return {
        "source_sha256": source_sha256(sources),
        "source_modules": [name for name, _ in sources],
        "plugins": plugins,
        "versions": versions(),
        "data_sha256": {
            p.name: hashlib.sha256(p.read_bytes()).hexdigest() for p in (OBLIQUE, GO_NO_GO)
        },  # fmt: skip
    }


def _recorded(path: Path) -> object:
    """The provenance written beside the outputs, or None (none, unreadable)."""
    try:
        return load_json(path.read_bytes(), str(path))
    except (OSError, PlateImpactError):
        return None


def outputs(out: Path, suffix: str = "png") -> list[Path]:
    """What :func:`experiment` writes into ``out``."""
    return [
        *(out / f"validate_SAE1010_1.47mm_{name}.{suffix}" for name in MODELS),
        out / f"v50_SAE1010_1.47mm.{suffix}",
        out / "pstar_table_SAE1010_1.47mm.csv",
    ]


def experiment(
    out: Path,
    dpi: float = saving.DPI,
    suffix: str = "png",
    resume: bool = False,
    quick: bool = False,
) -> list[Path]:
    """Draw the validation of both mild-steel models, the V50 fits beside the model's
    ballistic limits, and write the by-obliquity P* table (CSV with standard errors)
    into ``out``; returns the paths written. With ``resume``, what is there is kept
    while :data:`PROVENANCE` beside it says it was made by the code and shot files
    that would make it now; else everything is made again (and replaced). ``quick``
    (reproduce --quick): the table from the shots at one obliquity, its boundaries
    coarser (recorded in the provenance: a full run never keeps a quick one's outputs)."""
    plate, sphere = presets.plate(PLATE), presets.DEFAULT_SPHERE
    *validations, v50, table = outputs(out, suffix)
    record, written = provenance() | ({"quick": True} if quick else {}), out / PROVENANCE
    resume = resume and _recorded(written) == json.loads(json.dumps(record))
    if not resume:  # what is there is not what would be made now: forget its record first
        written.unlink(missing_ok=True)
    shots = pi.Shots.from_csv(OBLIQUE)
    for (name, failure), path in zip(MODELS.items(), validations, strict=True):
        if resume and path.exists():
            continue
        simulation = pi.Simulation.from_names(failure=failure)
        report = pi.validate(simulation, sphere, plate, shots)
        title = (f"{PLATE}, {name} model against {OBLIQUE.name} (synthetic): "
                 f"outcome agreement {report.agreement:.1%}")  # fmt: skip
        saving.save(validation_figure(report, simulation, title=title), str(path), dpi=dpi)
    if not (resume and v50.exists()):
        go_no_go = pi.Shots.from_csv(GO_NO_GO).groups_by_obliquity()
        bootstrap = {"bootstrap": QUICK_BOOTSTRAP} if quick else {}
        simulation = pi.Simulation.from_names()
        model = limits.along_speed(simulation, sphere, plate, list(go_no_go), (50.0, 2000.0))
        panels = [
            Panel(f"{math.degrees(obliquity):g} deg", group.impact_speed, group.perforated,
                  group.weight, pi.fit_v50(group.impact_speed, group.perforated, group.weight,
                                           **bootstrap),
                  line.ballistic_limit)
            for (obliquity, group), line in zip(go_no_go.items(), model.lines, strict=True)
        ]  # fmt: skip
        title = f"{GO_NO_GO.name} (synthetic)"
        figure = v50_figure(panels, title=title, model=f"{PLATE}, plugging")
        saving.save(figure, str(v50), dpi=dpi)
    if not (resume and table.exists()):
        # Boundaries to 0.1 m/s (no band of 4 m/s missed) are 30 times finer than the
        # shots' 3 m/s speed noise and the fit's 10 m/s scatter; the P* found differ
        # from those at the defaults (0.01, 1 m/s) by under 0.005 mm, a tenth of their
        # standard errors, in 8 s instead of 13.
        finder = {"resolution": 4.0, "tolerance": 0.1}
        fitting = shots
        if quick:
            finder = QUICK_FIT_FINDER
            groups = shots.groups_by_obliquity()
            nearest = min(groups, key=lambda o: abs(math.degrees(o) - QUICK_FIT_OBLIQUITY))
            fitting = groups[nearest]
        fitted = fit_pstar_by_obliquity(fitting, plate, sphere=sphere, **finder)
        write_text(table, fitted.csv_text(), "table")
    write_text(written, json.dumps(record, indent=1, sort_keys=True) + "\n", "provenance", "json")
    return outputs(out, suffix)


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--out", default=".", help="directory for the figures and the table")
    args = parser.parse_args()
    start = time.perf_counter()
    for path in experiment(Path(args.out)):
        print(f"wrote:   {path}")
    print(f"({time.perf_counter() - start:.1f} s)")


if __name__ == "__main__":
    main()
