"""
The report's Figures 30–31: a thin plate against one that never fails
=====================================================================

The 3.18-mm 2024-T3 plate of Figures 25–31, at 0, 30, 45 and 60°, run with its P*
(plugging) and with an "extremely large" P* (a plate that never fails, ``intact``):
the study ``plateimpact reproduce`` runs for that family (``plateimpact_studies``), and
the figure it draws. Then the crater sections of Figure 35 (the 9.53-mm 6061-T6 plate at
60°, 263 and 737 m/s).
"""

# %%
# The family's study
# ------------------
# 146 speeds from 50 to 1500 m/s at four obliquities, two variants: 1,168 scenes, run on
# the numpy path in about a second.
import numpy as np

from plateimpact.figures import exit_curves
from plateimpact_studies.fig25_31_2024t3_3_18mm import study
from plateimpact_studies.report_figures import craters_figure_35

family = study()
results = family.run()
print(family.description)
print(f"{family.scenes.size} scenes x {len(family.variants)} variants")

# %%
# Exit speed and obliquity against impact speed
# ---------------------------------------------
# Solid: the plate with its P*; dashed: the same plate that never fails. The strips
# under each panel give every run's outcome ranges; a curve stops where the outcome
# changes, and an embedded sphere has no exit, so embedment is in the strips only.
figure = exit_curves.plot_study(results)
figure

# %%
# The outcomes at 60°, counted from the runs
# ------------------------------------------
# One row per scene and run (``to_dataframe``: the unit in each column's name). At 60°
# the plate with its P* is perforated from some speed on; the plate that never fails
# never is: its spheres ricochet or embed.
frame = results.to_dataframe()
at_60 = frame[np.isclose(frame["impact_obliquity_deg"], 60.0)]
at_60.groupby(level="variant", sort=False)["outcome"].value_counts().unstack(fill_value=0)

# %%
# Crater sections: Figure 35
# --------------------------
# One scene at each speed, its path recorded; the section is the trace the sphere leaves
# in the plate (eqs 31–39), as deep as it went (``studies/report_figures.py`` draws it
# for the report's figures).
figure = craters_figure_35()
figure
