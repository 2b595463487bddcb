"""
Results in a notebook
=====================

A small batch on the 1.47-mm SAE 1010 plate of Table 1, its results as a notebook shows
them, the same results as an xarray Dataset and a pandas DataFrame, the plate's limits,
and a V50 fitted to go/no-go shots read from a file, beside the model's ballistic limit.

Every object shows itself in user units (m/s, degrees, mm, g): the last line of a cell
displays a compact table in a notebook (``_repr_html_``) and one line of text elsewhere
(``repr``). Inside, values stay SI, as everywhere in the Python API.
"""

# %%
# A batch of scenes
# -----------------
# Four speeds at three obliquities, for the default sphere (a 6.35-mm steel ball).
# ``SceneBatch.grid`` takes SI: obliquities in radians, so the degrees are converted.
import importlib.resources

import numpy as np

import plateimpact as pi
from plateimpact import presets
from plateimpact.units import deg

sphere = presets.DEFAULT_SPHERE
plate = presets.plate("SAE1010/1.47")
speeds = np.array([200.0, 300.0, 450.0, 700.0])  # [m/s]
obliquities_deg = np.array([0.0, 45.0, 60.0])
batch = pi.SceneBatch.grid(sphere, plate, speeds, obliquities_deg * deg)
batch

# %%
# The results: what each scene ended in
# -------------------------------------
# ``run_batch`` keeps the scenes with the results, so that tables show the inputs beside
# the outcomes.
simulation = pi.Simulation.from_names()
results = simulation.run_batch(batch)
results

# %%
# One scene, with its path: the sphere at 450 m/s and 60 degrees.
scene = pi.Scene(sphere, plate, 450.0, 60 * deg)
result = simulation.run(scene, record_trajectory=True)
result

# %%
# A trajectory says how many samples it has, over what time and how it ended; it does
# not print its arrays (``result.trajectory.speed`` is one).
result.trajectory

# %%
# Labelled tables
# ---------------
# As an xarray Dataset: SI values with CF ``units``, the scenes' inputs as coordinates,
# as the archive's run files hold them.
dataset = results.to_xarray()
dataset

# %%
# As a pandas DataFrame: user units, each column named with its unit, the outcome by
# name; the same table ``plateimpact export --to FILE.csv`` writes.
frame = results.to_dataframe()
frame[["impact_speed_m_s", "impact_obliquity_deg", "outcome", "exit_speed_m_s"]]

# %%
# Counts of each outcome by obliquity, with pandas.
outcomes = frame.groupby("impact_obliquity_deg", observed=False)["outcome"].value_counts()
outcomes.unstack()

# %%
# The plate's limits
# ------------------
# Every outcome band along speed at 0 and 45 degrees, each boundary located to 0.01 m/s.
limits = pi.limits.along_speed(simulation, sphere, plate, [0.0, 45 * deg], (100.0, 1000.0))
limits

# %%
limits.to_dataframe()

# %%
# A V50 from go/no-go shots
# -------------------------
# ``Shots.from_csv`` reads a shot file (this one is synthetic: see its header); the
# fits take the shots as they are, one obliquity at a time.
data = importlib.resources.files("plateimpact_studies") / "data"
with importlib.resources.as_file(data / "gonogo_SAE1010_1.47mm.csv") as path:
    shots = pi.Shots.from_csv(path)
normal = shots.groups_by_obliquity()[0.0]
fit = pi.fit_v50(normal, bootstrap=200)
fit

# %%
# The same fit from the columns as arrays, and the model's ballistic limit at normal
# incidence beside it [m/s].
same = pi.fit_v50(normal.impact_speed, normal.perforated, normal.weight, bootstrap=200)
model_limit = limits.lines[0].ballistic_limit
print(f"V50 {fit.v50_m_s:.1f} m/s (arrays: {same.v50_m_s:.1f} m/s); model {model_limit:.2f} m/s")
