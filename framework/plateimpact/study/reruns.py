"""What a study does with runs its archive already has: reruns are explicit (docs/archive.md).

A variant's run is stored under its name (or the one ``run_names`` gives it). If the
study's archive already has a run of that name, the study keeps it (``resume``, when
its recorded plug-ins and settings are the variant's and its recorded code is the code
the variant would run now), replaces it (``overwrite``, atomically) or is refused
before anything runs; never a silent ``NAME.2``, never a stale run kept or replaced
unasked.
"""

from __future__ import annotations

from collections.abc import Mapping
from typing import TYPE_CHECKING, Any

import attrs

from ..base.errors import ArchiveError, ParameterError
from ..base.untrusted import load_json, printable
from ..provenance.code import changes, plugins_record
from ..registry.plugin_registry import PluginRegistry
from ..run.variant import Variant
from ..storage.append import RunExistsError, StudyDefinition, check_same_scenes

#: How a caller of the Python API proceeds past a stale run.
API_ADVICE = "overwrite=True replaces it, run_names stores the new run under another name"


class StaleRunError(RunExistsError):
    """A run that ``resume`` would keep was computed by other code than the variant would
    run now (a plug-in or the core changed, or the run records no provenance): it is
    neither kept nor replaced unasked. ``what`` says which run and what changed;
    the message adds how to proceed."""

    def __init__(self, what: str, advice: str = API_ADVICE) -> None:
        super().__init__(f"{what}; {advice}")
        self.what = what


if TYPE_CHECKING:
    from ..storage.archive import Archive


@attrs.frozen
class PlannedRun:
    """Where a variant's run goes: ``run`` (its name in the study); ``kept``, the stored
    run to read back instead of running (``STUDY/RUN``); ``replace``, whether the new
    run replaces a stored one."""

    run: str
    kept: str | None = None
    replace: bool = False


def plan_runs(
    archive: Archive | None,
    study: StudyDefinition,
    run_names: Mapping[str, str] | None = None,
    resume: bool = False,
    overwrite: bool = False,
    registry: PluginRegistry | None = None,
) -> dict[str, PlannedRun]:
    """Each variant's :class:`PlannedRun`, by variant name; :class:`RunExistsError`
    (before any run) for a name taken without ``resume`` or ``overwrite``, or taken by
    other plug-ins or settings with ``resume``; :class:`StaleRunError` for a run
    ``resume`` would keep whose recorded code (``plugins``) is not what the variant
    would run now with ``registry``'s plug-ins."""
    if resume and overwrite:
        raise ParameterError(
            "overwrite", "resume keeps stored runs and overwrite replaces them: give one"
        )
    if (resume or overwrite) and archive is None:
        raise ParameterError("resume", "resume and overwrite need the archive the runs are in")
    given = dict(run_names or {})
    unknown = set(given) - {v.name for v in study.variants}
    if unknown:
        raise ParameterError(
            "run_names", f"run_names names no variant of the study: {', '.join(sorted(unknown))}"
        )
    names = {v.name: given.get(v.name, v.name) for v in study.variants}
    for name in names.values():
        if not name or name != name.strip() or "/" in name or not name.isprintable():
            raise ParameterError(
                "run_names",
                f"run names must be printable, without '/' or surrounding space, got {name!r}",
            )
    if len(set(names.values())) < len(names):
        raise ParameterError("run_names", "two variants would be stored under one run name")
    stored = _stored_variants(archive, study) if archive is not None else {}
    planned = {}
    for variant in study.variants:
        name = names[variant.name]
        if name not in stored:
            planned[variant.name] = PlannedRun(name)
        elif resume and stored[name] == variant:
            assert archive is not None
            _check_code(archive, f"{study.name}/{name}", variant, registry)
            planned[variant.name] = PlannedRun(name, kept=f"{study.name}/{name}")
        elif overwrite:
            planned[variant.name] = PlannedRun(name, replace=True)
        else:
            assert archive is not None
            other = " with other plug-ins or settings" if resume else ""
            raise RunExistsError(
                f"archive {archive.path} already has run {study.name}/{name}{other}: keep it "
                "(resume), replace it (overwrite) or store the new run under another name"
            )
    return planned


def _stored_variants(archive: Archive, study: StudyDefinition) -> dict[str, Variant]:
    """The study's stored runs and their recorded variants, by run name (the scenes
    checked to be the study's)."""
    if not archive.real.exists() or study.name not in archive.studies():
        return {}
    with archive._open() as f, archive._linked(f, f"{study.name}/scenes") as scenes:
        check_same_scenes(scenes, study, archive.path)
    found = {}
    for run in archive.runs():
        owner, name = run.split("/", 1)
        if owner == study.name:
            found[name] = archive.recorded_variant(run)
    return found


def _check_code(
    archive: Archive, run: str, variant: Variant, registry: PluginRegistry | None
) -> None:
    current = plugins_record(variant.simulation(registry))
    text = archive._attributes(run).get("plugins")
    check_code(f"archive {archive.path}: run {printable(run)}", text, current)


def check_code(label: str, recorded: object, current: Mapping[str, Any]) -> None:
    """Refuse to keep what ``label`` names unless its ``recorded`` ``plugins`` attribute
    (JSON text, untrusted; None if absent) is the ``current`` code's. One recorded
    before plug-in provenance was cannot be checked, so it is refused too: keeping it
    could keep stale results, and replacing it would lose a finished result."""
    if recorded is None:
        raise StaleRunError(
            f"{label} records no plug-in provenance (written before plateimpact recorded "
            "it), so whether resume would run the same code is unknown"
        )
    text = recorded if isinstance(recorded, bytes) else str(recorded)
    found = changes(load_json(text, f"{label}: attribute plugins", ArchiveError), current)
    if found:
        raise StaleRunError(f"{label} was made by other code than resume would run "
                            f"({'; '.join(found)})")  # fmt: skip
