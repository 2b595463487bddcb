"""
The model against shots: validate and V50
=========================================

The shot files shipped with the studies (``studies/data``, installed with them): oblique
shots of the 1.47-mm SAE 1010 plate with residual speeds and exit obliquities, and
go/no-go shots at 0 and 45°. Both are **synthetic**: made from the model with stated
noise (their headers say how), so what this shows is that the tools give back what was
put in (docs/experiment.md). ``plateimpact reproduce`` draws the same figures.
"""

# %%
# Oblique shots, validated against two models
# -------------------------------------------
# ``validate`` runs every shot's scene and compares outcome, residual speed and exit
# obliquity. The shots were made with the variable-P* model: it agrees with them, the
# constant-P* one (plugging at P* = 4.6 mm) much less.
import importlib.resources
import math

import plateimpact as pi
from plateimpact import limits, presets
from plateimpact.figures.v50_fits import Panel, v50_figure
from plateimpact.figures.validation_panels import validation_figure

data = importlib.resources.files("plateimpact_studies") / "data"
with importlib.resources.as_file(data / "oblique_SAE1010_1.47mm_variable_pstar.csv") as path:
    oblique = pi.Shots.from_csv(path)
with importlib.resources.as_file(data / "gonogo_SAE1010_1.47mm.csv") as path:
    go_no_go = pi.Shots.from_csv(path)
plate, sphere = presets.plate("SAE1010/1.47"), presets.DEFAULT_SPHERE

reports = {}
for failure in ("variable-pstar", "plugging"):
    simulation = pi.Simulation.from_names(failure=failure)
    reports[failure] = pi.validate(simulation, sphere, plate, oblique)
    print(f"{failure:>15}: outcome agreement {reports[failure].agreement:.1%}")

# %%
# The variable-P* model's panels: measured against predicted, shot by shot.
report = reports["variable-pstar"]
title = f"SAE 1010, 1.47 mm, variable-P* model: agreement {report.agreement:.1%}"
simulation = pi.Simulation.from_names(failure="variable-pstar")
figure = validation_figure(report, simulation, title=title)
figure

# %%
# V50 at each obliquity, beside the model's ballistic limit
# ---------------------------------------------------------
# The probit fit of each obliquity's go/no-go shots (with bootstrap intervals), and the
# ballistic limit the model's finder locates at the same obliquity: the shots were drawn
# around it, so each V50 lies near it.
groups = go_no_go.groups_by_obliquity()
model = limits.along_speed(pi.Simulation.from_names(), sphere, plate, list(groups))
panels = []
for (obliquity, group), line in zip(groups.items(), model.lines, strict=True):
    fit = pi.fit_v50(group, bootstrap=200)
    print(f"{math.degrees(obliquity):g} deg: {fit!r}; model {line.ballistic_limit:.2f} m/s")
    panels.append(
        Panel(
            f"{math.degrees(obliquity):g} deg",
            group.impact_speed,
            group.perforated,
            group.weight,
            fit,
            line.ballistic_limit,
        )
    )
figure = v50_figure(panels, title="gonogo_SAE1010_1.47mm.csv (synthetic)", model="plugging")
figure
