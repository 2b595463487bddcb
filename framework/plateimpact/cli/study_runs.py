"""Runs of one study of an archive, named as users name them (``compare``, ``plot``)."""

from __future__ import annotations

from ..storage.archive import Archive
from ..study.study import Study, StudyResults
from .common import UsageError


def study_results(archive: Archive, runs: list[str]) -> StudyResults:
    """The runs (STUDY/RUN, or RUN when unique) of one study."""
    names = [archive.resolve(run) for run in runs]
    studies = {name.split("/", 1)[0] for name in names}
    if len(studies) != 1:
        raise UsageError(f"runs of one study only, got {', '.join(sorted(names))}")
    study = Study.from_archive(archive.path, studies.pop())
    return StudyResults(study, {name: archive.results(name) for name in names})
