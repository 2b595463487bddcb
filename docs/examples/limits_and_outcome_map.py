"""
Limits and an outcome map
=========================

Every outcome band of a plate, its boundaries located to a tolerance rather than read
off a grid (docs/limits.md): the ballistic and ricochet limits of the 3.18-mm 2024-T3
plate at four obliquities, the bands drawn, and the plate's outcome map over speed and
obliquity, from which its limit curves are read.
"""

# %%
# Limits along impact speed
# -------------------------
# At each obliquity the finder scans the speed range, then bisects every outcome change
# to 0.01 m/s (the default tolerance). The plate with the report's plugging model.
import numpy as np

import plateimpact as pi
from plateimpact import limits, presets
from plateimpact.figures.limits_and_maps import plot_bands, plot_limit_curves, plot_outcome_map

sphere = presets.DEFAULT_SPHERE
plate = presets.plate("2024-T3/3.18")
simulation = pi.Simulation.from_names()
found = limits.along_speed(simulation, sphere, plate, np.radians([0, 30, 45, 60]))
found

# %%
# One row per obliquity: the ballistic limit (the start of the last run of perforation),
# the lowest perforating speed and the highest ricochet speed (docs/limits.md).
found.to_dataframe()

# %%
# The bands of each line, coloured by regime (ricochet before or after the plate fails,
# embedment, perforation), with the located boundaries.
figure = plot_bands(found, "2024-T3, 3.18 mm")
figure

# %%
# An outcome map
# --------------
# Outcomes on a grid of speed and obliquity, each cell's boundary with its neighbours
# located along speed. A coarse map here (18 obliquities × 50 speeds, boundaries to
# 0.1 m/s) so that it runs in a second; ``plateimpact map`` draws 86 × 200 by default.
outcome_map = limits.outcome_map(
    simulation,
    sphere,
    plate,
    speed_samples=50,
    obliquities=np.radians(np.arange(0.0, 86.0, 5.0)),
    tolerance=0.1,
)
outcome_map

# %%
figure = plot_outcome_map([("2024-T3, 3.18 mm", outcome_map)])
figure

# %%
# Limit curves
# ------------
# The ballistic and ricochet limits against obliquity, read from the map: the lines the
# finder located above lie on them.
figure = plot_limit_curves([("2024-T3, 3.18 mm", outcome_map)])
figure
