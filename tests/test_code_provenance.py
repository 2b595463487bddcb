"""Which code made a result: every output records each plug-in's distribution, version and
source hash, and the core's; a resumed study keeps a stored run only if that record is
the code it would run now (docs/archive.md, "Provenance").

The plug-in whose code changes is a copy of tests/third_party in ``tmp_path``, installed
as far as entry points can tell (its .dist-info beside it), edited and loaded again, as
a colleague's reinstalled package would be.
"""

from __future__ import annotations

import hashlib
import importlib
import importlib.util
import json
import shutil
import sys
import types
from pathlib import Path

import attrs
import numpy as np
import pytest
from conftest import THIRD_PARTY

import plateimpact as pi
from plateimpact import limits, presets
from plateimpact.cli import main
from plateimpact.provenance import code as code_provenance
from plateimpact.storage.upgrade import upgrade
from plateimpact.study.reruns import StaleRunError

PACKAGE = "plateimpact_isotropic"
BUILTINS = Path(__file__).resolve().parents[1] / "plugins" / "plateimpact_plugins"
FORMAT1 = Path(__file__).parent / "data" / "format1.h5"
PLATE = attrs.evolve(presets.plate("6061-T6/9.53"), rate_sensitivity=0.3)
VARIANT = pi.Variant(
    "rate", resistance="rate-poncelet", resistance_settings={"reference_speed": 50.0}
)
#: The line of the rate law that the "new release" changes (and so its results).
LAW = "strength = scenes.a * (1.0 + scenes.rate_sensitivity * rate)"


def sha256_of_modules(modules: dict[str, Path]) -> str:
    """The documented hash, written out: SHA-256 over the sorted lines
    ``MODULE SHA256-OF-ITS-FILE``."""
    lines = "".join(
        f"{name} {hashlib.sha256(path.read_bytes()).hexdigest()}\n"
        for name, path in sorted(modules.items())
    )
    return hashlib.sha256(lines.encode()).hexdigest()


def isotropic_sha256(site: Path) -> str:
    """The rate law's source hash, from the rule: its module (the package's __init__), the
    package's modules that imports (its failure model and integrator), what they import
    from the built-ins' package by name, plateimpact_plugins.report, and what that imports
    (its constants, the failure plane, the P* table), with the enclosing package's
    __init__ (not followed: the built-in plug-ins themselves)."""
    modules = {
        PACKAGE: site / PACKAGE / "__init__.py",
        "plateimpact_plugins": BUILTINS / "__init__.py",
        "plateimpact_plugins.report": BUILTINS / "report" / "__init__.py",
    }
    for path in (site / PACKAGE).glob("*.py"):
        if path.stem != "__init__":
            modules[f"{PACKAGE}.{path.stem}"] = path
    for stem in ("constants", "plane", "pstar_table"):
        modules[f"plateimpact_plugins.report.{stem}"] = BUILTINS / "report" / f"{stem}.py"
    return sha256_of_modules(modules)


@pytest.fixture
def site(tmp_path, monkeypatch):
    """A copy of the third-party package and its .dist-info, first on the path."""
    where = tmp_path / "site"
    for name in (PACKAGE, f"{PACKAGE}-0.1.dist-info"):
        shutil.copytree(THIRD_PARTY / name, where / name)
    monkeypatch.setattr(sys, "dont_write_bytecode", True)  # no stale .pyc after an edit
    monkeypatch.syspath_prepend(str(where))
    saved = sys.modules.pop(PACKAGE, None)
    pi.default_registry.cache_clear()
    yield where
    sys.modules.pop(PACKAGE, None)
    if saved is not None:
        sys.modules[PACKAGE] = saved
    pi.default_registry.cache_clear()


def installed() -> pi.PluginRegistry:
    """The plug-ins as a new process would load them now (the package imported afresh)."""
    sys.modules.pop(PACKAGE, None)
    importlib.invalidate_caches()
    return pi.load_registry()


def rate_study() -> pi.Study:
    return pi.Study.grid("rate", [PLATE], [0, 45], np.linspace(200.0, 900.0, 5), VARIANT)


def files_of(path: Path) -> dict[str, bytes]:
    """An archive's index and data files, byte for byte."""
    found = {path.name: path.read_bytes()}
    found |= {p.name: p.read_bytes() for p in Path(f"{path}.d").iterdir()}
    return found


# -- resume --------------------------------------------------------------------------------


def test_a_changed_plug_in_is_refused_on_resume_and_an_unchanged_one_resumed(
    site, tmp_path, chunks
):
    study, path = rate_study(), tmp_path / "a.h5"
    first = study.run(archive=path, registry=installed())
    assert sum(chunks) == study.scenes.size
    recorded = pi.Archive(path).metadata("rate")["plugins"]["resistance"]
    old = isotropic_sha256(site)
    assert recorded["source_sha256"] == old
    assert (recorded["distribution"], recorded["distribution_version"]) == (
        "plateimpact-isotropic", "0.1",
    )  # fmt: skip
    assert recorded["entry_point"] == "isotropic = plateimpact_isotropic"
    # The same code loaded again: the run is read back, no scene computed.
    chunks.clear()
    again = study.run(archive=path, resume=True, registry=installed())
    assert chunks == []
    np.testing.assert_array_equal(again["rate"].exit_speed, first["rate"].exit_speed)
    # A new release of the law: resume refuses, before any scene, and changes nothing.
    source = site / PACKAGE / "__init__.py"
    source.write_text(source.read_text().replace(LAW, LAW.replace("(1.0 + ", "(1.0 + 2.0 * ")))
    new, registry, before = isotropic_sha256(site), installed(), files_of(path)
    assert new != old
    for attempt in (study.check_archive, study.run):
        with pytest.raises(StaleRunError) as refused:
            attempt(archive=path, resume=True, registry=registry)
        message = str(refused.value)
        assert message == (
            f"archive {path}: run rate/rate was made by other code than resume would run "
            f"(resistance rate-poncelet: source sha256 {old[:12]} -> {new[:12]}); "
            "overwrite=True replaces it, run_names stores the new run under another name"
        )
    assert chunks == [] and files_of(path) == before
    # Told to, it replaces the run with one the new code computes, which differs.
    replaced = study.run(archive=path, overwrite=True, registry=registry)
    assert sum(chunks) == study.scenes.size
    assert not np.array_equal(replaced["rate"].exit_speed, first["rate"].exit_speed)
    stored = pi.Archive(path).metadata("rate")["plugins"]["resistance"]["source_sha256"]
    assert stored == new
    chunks.clear()
    study.run(archive=path, resume=True, registry=registry)
    assert chunks == []


def test_a_new_version_of_the_distribution_is_refused_on_resume(site, tmp_path, chunks):
    study, path = rate_study(), tmp_path / "a.h5"
    study.run(archive=path, registry=installed())
    metadata = site / f"{PACKAGE}-0.1.dist-info" / "METADATA"
    metadata.write_text(metadata.read_text().replace("Version: 0.1", "Version: 0.2"))
    chunks.clear()
    with pytest.raises(StaleRunError, match=r"resistance rate-poncelet: distribution version "
                                            r"0\.1 -> 0\.2\); overwrite"):  # fmt: skip
        study.run(archive=path, resume=True, registry=installed())
    assert chunks == []
    # As another run beside it: both kept, each with the code that made it.
    study.run(archive=path, run_names={"rate": "rate@0.2"}, registry=installed())
    archive = pi.Archive(path)
    assert archive.runs() == ["rate/rate", "rate/rate@0.2"]
    versions = [archive.metadata(r)["plugins"]["resistance"]["distribution_version"]
                for r in archive.runs()]  # fmt: skip
    assert versions == ["0.1", "0.2"]


def test_a_run_recorded_before_plug_in_provenance_is_refused_on_resume(tmp_path, chunks):
    path = tmp_path / "old.h5"
    shutil.copy(FORMAT1, path)
    upgrade(
        path, registry=pi.default_registry()
    )  # format 2, its runs' attributes copied as they were: no plugins
    before = files_of(path)
    with pytest.raises(StaleRunError) as refused:
        pi.Study.from_archive(path).run(archive=path, resume=True)
    assert str(refused.value) == (
        f"archive {path}: run v1/plugging records no plug-in provenance (written before "
        "plateimpact recorded it), so whether resume would run the same code is unknown; "
        "overwrite=True replaces it, run_names stores the new run under another name"
    )
    assert chunks == [] and files_of(path) == before


def test_a_stale_stored_map_stops_reproduce_resume_before_anything_runs(tmp_path, capsys):
    out = tmp_path / "report"
    out.mkdir()
    archive = out / "report.h5"
    plate = next(iter(presets.PLATES))
    found = limits.along_speed(
        pi.Simulation.from_names(), presets.DEFAULT_SPHERE, presets.plate(plate), [0.0],
        (50.0, 200.0), tolerance=1.0, resolution=20.0,
    )  # fmt: skip
    assert found.plugins == {
        **code_provenance.plugins_record(pi.Simulation.from_names()),
        "limits": code_provenance.limits_record(),
    }
    core = dict(found.plugins["core"], source_sha256="0" * 64)  # made by another core
    name = f"map_{plate.replace('/', '_')}"
    limits.archive_limits(
        archive, name, attrs.evolve(found, plugins={**found.plugins, "core": core})
    )
    before, listed = files_of(archive), sorted(out.iterdir())
    assert main(["reproduce", "--out", str(out), "--resume"]) == 2
    err = capsys.readouterr().err.splitlines()
    now = found.plugins["core"]["source_sha256"][:12]
    assert err == [
        f"plateimpact: error: archive {archive}: limits/{name} was made by other code than "
        f"resume would run (core: source sha256 000000000000 -> {now}); --overwrite replaces "
        "it, --as TAG stores the new runs as VARIANT@TAG (and the maps as map_PLATE@TAG)"
    ]
    assert files_of(archive) == before and sorted(out.iterdir()) == listed  # no figure drawn


# -- what is recorded ------------------------------------------------------------------------


def test_every_output_records_the_code_that_made_it(tmp_path, capsys):
    simulation = pi.Simulation.from_names(failure="hinge", integrator="segment")
    record = code_provenance.plugins_record(simulation)
    assert set(record) == {"core", "resistance", "failure", "integrator"}
    # Each hash is the documented one over the modules it lists, wherever they are.
    for entry in record.values():
        files = {m: Path(importlib.util.find_spec(m).origin) for m in entry["source_modules"]}
        assert entry["source_sha256"] == sha256_of_modules(files)
    assert record["failure"]["source_modules"] == [
        "plateimpact_plugins", "plateimpact_plugins.hinge", "plateimpact_plugins.report",
        "plateimpact_plugins.report.constants", "plateimpact_plugins.report.plane",
        "plateimpact_plugins.separation",
    ]  # fmt: skip
    assert record["integrator"]["class"] == "plateimpact_plugins.segment.Segment"
    assert record["integrator"]["distribution"] == "plateimpact"
    core = record["core"]["source_modules"]
    assert {
        "plateimpact.run.simulation",
        "plateimpact.model.impact",
        "plateimpact.solve.driver",
    } <= set(core)
    assert not any(m.startswith(("plateimpact.cli", "plateimpact.storage")) for m in core)
    # run --json (and so sweep's FILE.json) and the archive's run attribute.
    argv = ["run", "--preset", "2024-T3/3.18", "--speed", "640", "--obliquity", "60"]
    # (segment at a coarse step: the record is the code's, whatever the settings)
    argv += ["--failure", "hinge", "--integrator", "segment", "--set", "integrator.step=0.02"]
    argv += ["--json"]
    assert main(argv) == 0
    printed = capsys.readouterr().out
    assert json.loads(printed)["inputs"]["plugins"] == record
    saved = tmp_path / "run.json"
    saved.write_text(printed)
    assert main(["run", "--inputs", str(saved), "--json"]) == 0  # read back, provenance aside
    assert capsys.readouterr().out == printed
    variant = pi.Variant(
        "v", failure="hinge", integrator="segment", integrator_settings={"step": 0.02}
    )
    pi.Study.grid("s", ["2024-T3/3.18"], [0], [640.0], variant).run(archive=tmp_path / "a.h5")
    assert pi.Archive(tmp_path / "a.h5").metadata("v")["plugins"] == record


def test_stored_limits_keep_their_record_and_older_ones_read_without_it(tmp_path):
    found = limits.along_speed(
        pi.Simulation.from_names(), presets.DEFAULT_SPHERE, presets.plate("2024-T3/1.27"),
        [0.0], (50.0, 200.0), tolerance=1.0, resolution=20.0,
    )  # fmt: skip
    assert found.to_json()["plugins"] == found.plugins
    modules = found.plugins["limits"]["source_modules"]
    assert {"plateimpact.limits.plate_limits", "plateimpact.limits.regimes"} <= set(modules)
    limits.archive_limits(tmp_path / "a.h5", "l", found)
    assert limits.read_limits(tmp_path / "a.h5", "l").plugins == found.plugins
    record = limits.archived.to_record(found)
    del record.attributes["plugins"]  # as written before plug-in provenance was
    assert limits.archived.from_record(record).plugins is None


def test_hashes_are_computed_once_per_class_and_process(monkeypatch):
    simulation = pi.Simulation.from_names(failure="variable-pstar", integrator="solve_ivp")
    first = code_provenance.plugins_record(simulation)
    calls = []
    monkeypatch.setattr(code_provenance, "module_sources", lambda *a: calls.append(a) or ())
    assert code_provenance.plugins_record(simulation) == first and calls == []


def test_the_hash_names_modules_not_places(tmp_path, monkeypatch):
    """The same package at two places (a source tree, an install) hashes alike; one
    changed byte does not."""
    hashes = []
    for place, extra in (("tree", ""), ("installed", ""), ("edited", " ")):
        where = tmp_path / place
        shutil.copytree(THIRD_PARTY / PACKAGE, where / PACKAGE)
        (where / PACKAGE / "__init__.py").write_text(
            (THIRD_PARTY / PACKAGE / "__init__.py").read_text() + extra
        )
        monkeypatch.setattr(sys, "path", [str(where), *sys.path])
        monkeypatch.setattr(sys, "dont_write_bytecode", True)
        monkeypatch.delitem(sys.modules, PACKAGE, raising=False)
        importlib.invalidate_caches()
        module = importlib.import_module(PACKAGE)
        hashes.append(code_provenance.plugin_record(module.RatePoncelet)["source_sha256"])
        assert code_provenance.plugin_record(module.RatePoncelet)["distribution"] is None
    assert hashes[0] == hashes[1] != hashes[2]


# -- show ------------------------------------------------------------------------------------


def test_show_prints_each_runs_code(site, tmp_path, capsys):
    path = tmp_path / "a.h5"
    rate_study().run(archive=path, registry=installed())
    assert main(["show", str(path)]) == 0
    lines = capsys.readouterr().out.splitlines()
    record = pi.Archive(path).metadata("rate")["plugins"]
    shown = [line for line in lines if line.startswith("  code: ")]
    version = record["core"]["version"]  # plateimpact's, which also ships the built-ins

    def short(slot: str) -> str:
        return record[slot]["source_sha256"][:12]

    assert shown == [
        f"  code: core plateimpact {version}, source {short('core')}",
        f"  code: resistance rate-poncelet from plateimpact-isotropic 0.1, "
        f"source {isotropic_sha256(site)[:12]}",
        f"  code: failure plugging from plateimpact {version}, source {short('failure')}",
        f"  code: integrator dopri5 from plateimpact {version}, source {short('integrator')}",
    ]
    assert main(["show", str(FORMAT1)]) == 0  # a run from before: said, not guessed
    out = capsys.readouterr().out
    old = pi.Archive(FORMAT1)  # its runs and its stored limits
    assert out.count("  code: no plug-in provenance recorded") == len(old.runs()) + len(
        old.limits_names()
    )


def test_what_show_prints_of_a_record_is_made_safe():
    hostile = {"name": "x\x1b[2J\nplateimpact: error: forged", "distribution": "\u202eevil",
               "distribution_version": "1\r", "source_sha256": None}  # fmt: skip
    lines = code_provenance.summary({"core": "junk", "resistance": hostile})
    assert all(line.isprintable() for line in lines)
    assert lines[0] == "code: core not recorded"
    assert lines[1].startswith("code: resistance x") and "source unknown" in lines[1]


def test_experiment_outputs_are_kept_only_while_their_recorded_code_is_current(
    tmp_path, monkeypatch
):
    from plateimpact_studies import experiment  # noqa: PLC0415 (the studies, installed)

    made = experiment.outputs(tmp_path)
    for path in made:
        path.write_text(f"made before: {path.name}")
    record = tmp_path / experiment.PROVENANCE
    record.write_text(json.dumps(experiment.provenance()))

    class Computed(Exception):
        pass

    def computed(*args, **kwargs):
        raise Computed

    for name in ("validate", "fit_v50"):
        monkeypatch.setattr(pi, name, computed)
    monkeypatch.setattr(experiment, "fit_pstar_by_obliquity", computed)  # the report room's
    monkeypatch.setattr(limits, "along_speed", computed)
    assert experiment.experiment(tmp_path, resume=True) == made  # all kept, nothing computed
    assert all(p.read_text() == f"made before: {p.name}" for p in made)
    # Made from other shot files (or code): all made again, and its old record gone first.
    changed = json.loads(record.read_text())
    changed["data_sha256"][experiment.OBLIQUE.name] = "0" * 64
    record.write_text(json.dumps(changed))
    with pytest.raises(Computed):
        experiment.experiment(tmp_path, resume=True)
    assert not record.exists()


def test_a_plain_run_computes_no_record(monkeypatch, capsys):
    """``run`` without ``--json`` prints no provenance, so it computes none (no hash, no
    git): it costs what it did before the code was recorded."""
    from plateimpact.cli.commands import run as scene_commands  # noqa: PLC0415

    asked = []
    monkeypatch.setattr(scene_commands, "inputs_record", lambda *a, **k: asked.append(a) or {})
    argv = ["run", "--preset", "2024-T3/3.18", "--speed", "640", "--obliquity", "60"]
    assert main(argv) == 0 and asked == []
    assert main([*argv, "--json"]) == 0 and len(asked) == 1
    capsys.readouterr()


def test_a_plug_in_of_a_script_is_hashed_by_its_file_and_one_of_no_file_is_unknown(
    tmp_path, monkeypatch
):
    """A study script's own plug-in (its module ``__main__``, which has no spec) is its
    file; a class made by ``exec`` has none, and its code is unknown, not guessed."""
    script = tmp_path / "study.py"
    script.write_text("import numpy\n")
    for name, file in (("script_main", str(script)), ("made_by_exec", None)):
        module = types.ModuleType(name)
        module.__file__ = file
        monkeypatch.setitem(sys.modules, name, module)
    law = type("Law", (pi.ResistanceLaw,), {"name": "law", "__module__": "script_main"})
    assert code_provenance.plugin_record(law)["source_sha256"] == sha256_of_modules(
        {"script_main": script}
    )
    made = type("Made", (pi.ResistanceLaw,), {"name": "made", "__module__": "made_by_exec"})
    assert code_provenance.plugin_record(made)["source_sha256"] is None
    same = {"resistance": code_provenance.plugin_record(made)}  # recorded and now alike,
    assert code_provenance.changes(same, same) == [  # and still not known to be the same
        "resistance made: source unknown (recorded none, now none)"
    ]
