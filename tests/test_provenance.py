"""Provenance: every output carries every input, in user units, and the source commit.

The commit comes from the installed distribution's direct_url.json (PEP 610), never
from a repository that merely encloses site-packages; ``run --json`` reruns bit for bit
from its own output alone; a sweep's CSV has its inputs beside it; ``show`` prints a
run's model, scenes, versions and commit.
"""

from __future__ import annotations

import csv
import importlib.metadata
import io
import json
import math
import os
import subprocess

import numpy as np
import pytest

import plateimpact as pi
from plateimpact.cli import main
from plateimpact.model.bodies import MASS
from plateimpact.model.scene import IMPACT_OBLIQUITY
from plateimpact.provenance import metadata as provenance
from plateimpact.storage.plate_file import plate_from_dict, plate_to_dict

# -- the source commit ---------------------------------------------------------------


def git(directory, *args: str) -> str:
    clean = {k: v for k, v in os.environ.items() if not k.startswith("GIT_")}
    identity = ["-c", "user.name=t", "-c", "user.email=t@example.org", "-c", "commit.gpgsign=false"]
    done = subprocess.run(
        ["git", "-C", str(directory), *identity, *args],
        capture_output=True,
        text=True,
        check=True,
        env=clean,
    )
    return done.stdout.strip()


def checkout(path, *files: str) -> str:
    """A git repository at ``path`` with one commit (holding ``files``); its HEAD."""
    for name in ("README", *files):
        (path / name).parent.mkdir(parents=True, exist_ok=True)
        (path / name).write_text("x\n")
    git(path, "init", "-q")
    git(path, "add", ".")
    git(path, "commit", "-q", "-m", "one")
    return git(path, "rev-parse", "HEAD")


def installed(site, direct_url: dict | None) -> importlib.metadata.Distribution:
    """plateimpact installed into ``site`` (a package and its .dist-info), with this
    direct_url.json (None: installed from an index, which writes none)."""
    (site / "plateimpact").mkdir(parents=True)
    (site / "plateimpact" / "__init__.py").write_text("")
    info = site / "plateimpact-0.1.0.dist-info"
    info.mkdir()
    (info / "METADATA").write_text("Metadata-Version: 2.1\nName: plateimpact\nVersion: 0.1.0\n")
    if direct_url is not None:
        (info / "direct_url.json").write_text(json.dumps(direct_url))
    return importlib.metadata.PathDistribution(info)


@pytest.fixture
def install(monkeypatch):
    """Make importlib.metadata find the given distribution as plateimpact's."""
    real = importlib.metadata.distribution

    def use(distribution: importlib.metadata.Distribution | None) -> None:
        def find(name: str) -> importlib.metadata.Distribution:
            if name != "plateimpact":
                return real(name)
            if distribution is None:
                raise importlib.metadata.PackageNotFoundError(name)
            return distribution

        monkeypatch.setattr(importlib.metadata, "distribution", find)

    return use


def test_a_commit_pip_recorded_from_a_git_url_is_the_source_commit(tmp_path, install):
    commit = "0123456789abcdef0123456789abcdef01234567"
    url = {
        "url": "https://example.org/plateimpact.git",
        "vcs_info": {"vcs": "git", "commit_id": commit},
    }
    install(installed(tmp_path / "site", url))
    assert provenance.source_commit(tmp_path / "site" / "plateimpact") == commit


def test_an_install_from_a_local_checkout_asks_git_there(tmp_path, install):
    head = checkout(tmp_path / "src")
    install(installed(tmp_path / "site", {"url": (tmp_path / "src").as_uri(), "dir_info": {}}))
    assert provenance.source_commit(tmp_path / "site" / "plateimpact") == head


def test_an_editable_install_gives_its_checkouts_commit(tmp_path, install):
    head = checkout(tmp_path / "repo", "framework/plateimpact/__init__.py")
    url = {"url": (tmp_path / "repo").as_uri(), "dir_info": {"editable": True}}
    install(installed(tmp_path / "site", url))
    assert provenance.source_commit(tmp_path / "repo" / "framework" / "plateimpact") == head


def test_a_git_that_never_answers_leaves_the_commit_unknown_and_says_so(
    tmp_path, install, monkeypatch
):
    """git gets provenance.GIT_TIMEOUT (a guard against a hung git, far above what a busy
    machine's rev-parse takes); one that never answers is a warning, never a silent
    "unknown". The fake git never answers however fast the machine: no timing decides."""
    checkout(tmp_path / "src")
    install(installed(tmp_path / "site", {"url": (tmp_path / "src").as_uri(), "dir_info": {}}))
    hung = tmp_path / "bin" / "git"
    hung.parent.mkdir()
    hung.write_text("#!/bin/sh\nexec sleep 3600\n")
    hung.chmod(0o755)
    monkeypatch.setenv("PATH", f"{hung.parent}{os.pathsep}{os.environ['PATH']}")
    monkeypatch.setattr(provenance, "GIT_TIMEOUT", 0.5)
    said = r"git gave no answer in .*src within 0.5 s; the source commit is recorded as unknown"
    with pytest.warns(pi.PlateImpactWarning, match=said):
        assert provenance.source_commit(tmp_path / "site" / "plateimpact") == "unknown"


@pytest.mark.parametrize("source", ["index", "unpacked", "inside the enclosing repository"])
def test_a_repository_enclosing_site_packages_is_never_asked(tmp_path, install, source):
    """site-packages inside a repository of its own (a project's .venv): git asked there
    answers that repository's commit, which says nothing about plateimpact's source."""
    enclosing = checkout(tmp_path / "project")
    site = tmp_path / "project" / ".venv" / "lib" / "site-packages"
    (tmp_path / "unpacked").mkdir()
    (tmp_path / "project" / "sub").mkdir()
    url = {
        "index": None,
        "unpacked": {"url": (tmp_path / "unpacked").as_uri(), "dir_info": {}},
        "inside the enclosing repository": {
            "url": (tmp_path / "project" / "sub").as_uri(),
            "dir_info": {},
        },
    }[source]
    install(installed(site, url))
    assert git(site / "plateimpact", "rev-parse", "HEAD") == enclosing  # the trap is set
    assert provenance.source_commit(site / "plateimpact") == "unknown"


def test_a_source_tree_on_the_path_gives_its_own_checkouts_commit(tmp_path, install):
    """Code that is not the installed distribution's (a checkout on PYTHONPATH): the
    checkout of this project that holds it; any other repository: unknown."""
    other = checkout(tmp_path / "installed-from")
    url = {"url": (tmp_path / "installed-from").as_uri(), "dir_info": {"editable": True}}
    install(installed(tmp_path / "site", url))
    head = checkout(tmp_path / "tree", "framework/plateimpact/__init__.py")
    assert head != other
    assert provenance.source_commit(tmp_path / "tree" / "framework" / "plateimpact") == head
    checkout(tmp_path / "elsewhere", "lib/plateimpact/__init__.py")
    assert provenance.source_commit(tmp_path / "elsewhere" / "lib" / "plateimpact") == "unknown"
    install(None)  # not installed at all
    assert provenance.source_commit(tmp_path / "tree" / "framework" / "plateimpact") == head


# -- exact numbers in user units ------------------------------------------------------


def test_user_numbers_parse_back_to_the_same_double_and_are_as_short_as_typed():
    rng = np.random.default_rng(17)
    for declared in (MASS, IMPACT_OBLIQUITY):
        for typed in [
            f"{x:.{d}g}"
            for x, d in zip(rng.uniform(0.01, 80, 300), rng.integers(1, 17, 300), strict=True)
        ]:
            si = declared.parse(typed)
            found = declared.user_number(si)
            assert found is not None and found * declared.scale == si, typed
            assert len(repr(found)) <= len(repr(float(typed))), (typed, found)
        for si in rng.uniform(1e-4, 1.5, 300):  # computed in SI: exact or refused
            found = declared.user_number(float(si))
            neighbours = [si / declared.scale]
            for direction in (math.inf, -math.inf):
                for _ in range(8):
                    neighbours.append(math.nextafter(neighbours[-1], direction))
                neighbours.append(si / declared.scale)
            reachable = any(v * declared.scale == si for v in neighbours)
            assert (found is not None) == reachable
            assert found is None or found * declared.scale == si


def test_plate_files_round_trip_exactly():
    plate = pi.presets.plate("2024-T3/3.18").with_constants(
        critical_penetration=2.7e-3, failure_angle=np.radians(40.0)
    )
    registry = pi.default_registry()
    data = plate_to_dict(plate, registry=registry)
    assert data["alpha_deg"] == 40 and data["pstar_mm"] == 2.7 and data["thickness_mm"] == 3.18
    back = plate_from_dict(json.loads(json.dumps(data)), registry=registry)
    assert back == plate  # the same bits


# -- run --json and --inputs ----------------------------------------------------------

RUN = ["run", "--preset", "2024-T3/3.18", "--speed", "640", "--obliquity", "60"]
CUSTOM = [
    "--radius", "3", "--mass", "0.9", "--a", "1.1e9", "--b", "1300", "--pstar", "2.7",
    "--alpha", "40", "--failure", "hinge", "--set", "failure.finger_area_scale=0.7",
    "--rtol", "1e-9", "--set", "model.rest_speed_fraction=0.02",
]  # fmt: skip


def run_json(capsys, *args: str) -> str:
    assert main([*args, "--json"]) == 0
    return capsys.readouterr().out


def test_run_json_records_every_input_as_typed(capsys):
    inputs = json.loads(run_json(capsys, *RUN, *CUSTOM))["inputs"]
    assert inputs["impact_speed_m_s"] == 640 and inputs["impact_obliquity_deg"] == 60
    assert inputs["sphere"] == {"radius_mm": 3, "mass_g": 0.9}
    plate = inputs["plate"]
    assert (plate["material"], plate["thickness_mm"], plate["a_N_m2"], plate["b_kg_m3"]) == (
        "2024-T3",
        3.18,
        1.1e9,
        1300,
    )
    assert (plate["pstar_mm"], plate["alpha_deg"]) == (2.7, 40)
    model = inputs["model"]
    assert (model["resistance"], model["failure"], model["integrator"]) == (
        "poncelet",
        "hinge",
        "dopri5",
    )
    assert model["failure_settings"]["finger_area_scale"] == 0.7
    assert model["integrator_settings"]["rtol"] == 1e-9
    assert model["rest_speed_fraction"] == 0.02
    assert set(inputs["versions"]) >= {"python", "plateimpact", "numpy", "scipy"}
    assert inputs["source_commit"] == provenance.source_commit()


@pytest.mark.parametrize(
    "options",
    [CUSTOM, ["--failure", "variable-pstar", "--integrator", "segment", "--step", "2e-2"]],
    ids=["custom", "variable-pstar"],
)
def test_run_json_reruns_bit_for_bit_from_itself_alone(tmp_path, capsys, options):
    first = run_json(capsys, *RUN, *options)
    assert (
        json.loads(first)["exit_speed_m_s"] != json.loads(run_json(capsys, *RUN))["exit_speed_m_s"]
    )
    saved = tmp_path / "run.json"
    saved.write_text(first)
    assert run_json(capsys, "run", "--inputs", str(saved)) == first  # every byte
    saved.write_text(json.dumps(json.loads(first)["inputs"]))  # the inputs object alone
    assert run_json(capsys, "run", "--inputs", str(saved)) == first


def test_a_mass_no_gram_value_reaches_is_recorded_in_kg(tmp_path, capsys):
    """A new radius keeps the default density: its mass is computed in SI, and some masses
    lie between the numbers of grams that * 1e-3 can reach."""
    radius = next(
        r
        for r in np.round(np.arange(2.0, 4.0, 0.01), 2)
        if MASS.user_number(pi.Sphere.of_density(r * 1e-3, pi.presets.SPHERE_DENSITY).mass) is None
    )
    first = run_json(capsys, *RUN, "--radius", str(radius))
    sphere = json.loads(first)["inputs"]["sphere"]
    assert set(sphere) == {"radius_mm", "mass_kg"}
    (tmp_path / "run.json").write_text(first)
    assert run_json(capsys, "run", "--inputs", str(tmp_path / "run.json")) == first


@pytest.mark.parametrize(
    ("change", "named"),
    [
        (lambda d: d["inputs"]["sphere"].update(radius_in=0.1), "sphere.radius_in: unknown key"),
        (lambda d: d["inputs"]["sphere"].update(radius_m=0.003), "radius_mm or radius_m, not both"),
        (lambda d: d["inputs"].pop("impact_speed_m_s"), "impact_speed_m_s: missing"),
        (lambda d: d["inputs"]["model"]["integrator_settings"].update(rtol="x"), "rtol"),
        (lambda d: d["inputs"]["plate"].update(pstar_mm=-1), "pstar_mm"),
        (lambda d: d["inputs"]["model"].update(failure="shatter"), "shatter"),
        (lambda d: d.update(inputs={"format": "x"}), "not a plateimpact inputs record"),
    ],
)
def test_a_bad_inputs_file_is_one_line_naming_the_key(tmp_path, capsys, change, named):
    data = json.loads(run_json(capsys, *RUN))
    change(data)
    (tmp_path / "run.json").write_text(json.dumps(data))
    assert main(["run", "--inputs", str(tmp_path / "run.json")]) == 2
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and "run.json" in err and named in err, err


def test_inputs_with_scene_or_model_options_is_refused(tmp_path, capsys):
    (tmp_path / "run.json").write_text(run_json(capsys, *RUN))
    for extra in (["--speed", "700"], ["--failure", "plugging"], ["--rtol", "1e-9"]):
        assert main(["run", "--inputs", str(tmp_path / "run.json"), *extra]) == 2
        err = capsys.readouterr().err
        assert err.count("\n") == 1 and f"--inputs cannot be combined with {extra[0]}" in err
    assert main(["run", "--preset", "2024-T3/3.18", "--speed", "640"]) == 2
    assert "--obliquity" in capsys.readouterr().err


# -- the sweep's sidecar ----------------------------------------------------------------

SWEEP = ["sweep", "--preset", "SAE1010/1.47", "--speeds", "300:900:3", "--obliquities", "0,45"]


def test_a_sweep_csv_has_its_inputs_beside_it_and_each_row_reruns(tmp_path, capsys):
    target = tmp_path / "steel.csv"
    assert main([*SWEEP, "--radius", "2.5", "--failure", "hinge", "--csv", str(target)]) == 0
    assert str(target) + ".json" in capsys.readouterr().out
    rows = list(csv.DictReader(target.open()))
    record = json.loads((tmp_path / "steel.csv.json").read_text())
    assert (record["speeds_m_s"], record["obliquities_deg"]) == ("300:900:3", "0,45")
    assert record["sphere"]["radius_mm"] == 2.5 and record["model"]["failure"] == "hinge"
    for row in (rows[1], rows[5]):
        scene = {k: v for k, v in record.items() if k not in ("speeds_m_s", "obliquities_deg")}
        scene["impact_speed_m_s"] = float(row["impact_speed_m_s"])
        scene["impact_obliquity_deg"] = float(row["impact_obliquity_deg"])
        (tmp_path / "scene.json").write_text(json.dumps(scene))
        rerun = json.loads(run_json(capsys, "run", "--inputs", str(tmp_path / "scene.json")))
        assert rerun["outcome"] == row["outcome"]
        assert rerun["exit_speed_m_s"] == float(row["exit_speed_m_s"])  # SI: the same bits


def test_a_sweep_to_standard_output_prints_only_its_csv(tmp_path, capsys, monkeypatch):
    monkeypatch.chdir(tmp_path)
    assert main(SWEEP) == 0
    rows = list(csv.reader(io.StringIO(capsys.readouterr().out)))
    assert len(rows) == 1 + 6 and rows[0][0] == "preset"
    assert list(tmp_path.iterdir()) == []


# -- show -------------------------------------------------------------------------------


def test_show_prints_a_runs_inputs_and_provenance(tmp_path, capsys):
    path = tmp_path / "a.h5"
    variant = pi.Variant(
        "finger", failure="hinge", failure_settings={"finger_area_scale": 0.5},
        integrator_settings={"rtol": 1e-9},
    )  # fmt: skip
    pi.Study.grid("s", ["2024-T3/3.18"], [0, 45], [300.0, 600.0], [variant]).run(archive=path)
    meta = pi.Archive(path).metadata("finger")
    assert main(["show", str(path)]) == 0
    out = capsys.readouterr().out
    assert "failure: hinge 1 (finger_area_scale 0.5, hinge_obliquity none)" in out
    assert "rtol 1e-09" in out and "max_seconds none, max_steps 20000" in out
    assert f"source commit {meta['git_commit']}" in out
    for name, version in meta["versions"].items():
        assert f"{name} {version}" in out
    assert "plates 2024-T3/3.18" in out and "impact_obliquity 0 deg, 45 deg" in out
    assert "thickness 3.18 mm" in out and "critical_penetration 3 mm" in out
