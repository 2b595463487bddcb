"""Studies: a named set of scenes run through one or more model variants into an archive
(study), and what a study does with the runs its archive already has (reruns).

>>> study = Study.grid("t318", ["2024-T3/3.18"], [0, 30, 60], speeds, [Variant("plugging")])
>>> results = study.run(archive="runs.h5")
"""

from __future__ import annotations

from .study import Study, StudyResults

__all__ = ["Study", "StudyResults"]
