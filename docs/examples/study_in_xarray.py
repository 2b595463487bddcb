"""
A study reviewed in xarray
==========================

A study is a grid of plates, obliquities and speeds run under one or more variants of
the model. Its results, read back from the HDF5 archive it was stored in, are one
labelled cube in xarray: one dimension per input, SI values with CF units, the plate
constants as coordinates (docs/archive.md, "In a notebook"). The archive here goes to a
temporary directory that is removed at the end.
"""

# %%
# Run a study into an archive
# ---------------------------
# Two plates of Table 1, four obliquities, 30 speeds, and two failure models: the
# report's plugging and the hinge (finger) model.
import tempfile
from pathlib import Path

import numpy as np

import plateimpact as pi

study = pi.Study.grid(
    "thin_plates",
    plates=["2024-T3/1.27", "2024-T3/3.18"],
    obliquities_deg=[0, 30, 45, 60],
    speeds=np.linspace(100.0, 1500.0, 30),
    variants=[pi.Variant("plugging"), pi.Variant("hinge", failure="hinge")],
    description="two thin aluminium plates, plugging against hinge failure",
)
folder = tempfile.TemporaryDirectory()
archive = Path(folder.name) / "thin_plates.h5"
study.run(archive=archive, progress=False)
print(f"{study.scenes.size} scenes x {len(study.variants)} variants stored in {archive.name}")

# %%
# Read it back as a Dataset
# -------------------------
# ``StudyResults.from_archive`` reads the study and every run; ``to_xarray`` labels them.
results = pi.StudyResults.from_archive(archive)
dataset = results.to_xarray()
dataset

# %%
# Select by label
# ---------------
# Values are SI (m/s, rad, m) and each variable says its unit. The exit speed of both
# models on the 1.27-mm plate at 45° (obliquity in radians: select the nearest):
exits = (
    dataset["exit_speed"]
    .sel(plate="2024-T3/1.27")
    .sel(impact_obliquity=np.radians(45.0), method="nearest")
)
print(exits.attrs["units"], exits.dims)
exits.isel(impact_speed=slice(None, None, 5)).to_pandas()

# %%
# Reduce over dimensions
# ----------------------
# The fraction of scenes perforated, per plate and variant: outcome codes are CF flags
# (``flag_values``, ``flag_meanings``), perforation among them.
meanings = dataset["outcome"].attrs["flag_meanings"].split()
perforation = dict(zip(meanings, dataset["outcome"].attrs["flag_values"], strict=True))
(dataset["outcome"] == perforation["perforation"]).mean(
    dim=["impact_obliquity", "impact_speed"]
).to_pandas()

# %%
# Plot straight from the cube
# ---------------------------
# xarray's own plotting: the maximum penetration [mm] against impact speed at every
# obliquity, one panel per plate, for the hinge model.
depth = dataset["max_penetration"].sel(variant="hinge") * 1e3
depth.attrs = {"long_name": "maximum penetration", "units": "mm"}
depth = depth.assign_coords(impact_obliquity=np.round(np.degrees(dataset["impact_obliquity"])))
depth["impact_obliquity"].attrs = {"long_name": "impact obliquity", "units": "deg"}
grid = depth.plot.line(x="impact_speed", hue="impact_obliquity", col="plate")

# %%
# The temporary archive goes when the script ends.
folder.cleanup()
