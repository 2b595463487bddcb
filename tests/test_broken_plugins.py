"""Broken plug-in packages: each is skipped with one warning line naming its distribution,
entry point and error; `plateimpact plugins` lists it as broken; none of its classes is
registered; the built-ins and the other third-party package keep working.

The broken packages are built on the fly, as tests/third_party is: a package directory
beside a ``NAME-VERSION.dist-info`` whose ``entry_points.txt`` entry points can find.
"""

from __future__ import annotations

import importlib
import os
import subprocess
import sys
from pathlib import Path

import pytest
from conftest import THIRD_PARTY

import plateimpact as pi
from plateimpact.cli import main

#: A valid resistance law with a plate constant of its own (and a flag for it): a package
#: that registers it and then fails must leave neither the law nor the constant behind.
LAW = '''
import attrs
from plateimpact import Parameter, Range, ResistanceLaw, hookimpl

HALF_STRENGTH = Parameter(
    "half_strength", "strength of the half law", "N/m^2", Range(0.0), default=1.0,
    flag="--half-strength",
)


@attrs.frozen
class HalfLaw(ResistanceLaw):
    """sigma = half_strength / 2."""

    name = "half-law"
    plate_constants = (HALF_STRENGTH,)

    def stress(self, speed, incidence, batch):
        return 0.5 * batch.half_strength + 0.0 * speed
'''

#: case -> (the module's source, or None for a malformed entry_points.txt; the start of
#: the error that the warning and `plugins` report)
BROKEN = {
    "import": (
        "import plateimpact_missing_dependency\n",
        "ModuleNotFoundError: No module named 'plateimpact_missing_dependency'",
    ),
    "syntax": ("def plateimpact_register(registry:\n", "SyntaxError: "),
    "hook-raises": (
        LAW
        + "@hookimpl\ndef plateimpact_register(registry):\n"
        + "    registry.add(HalfLaw)\n"
        + "    raise RuntimeError('licence server unreachable')\n",
        "RuntimeError: licence server unreachable",
    ),
    "invalid-class": (
        LAW
        + "@hookimpl\ndef plateimpact_register(registry):\n"
        + "    registry.add(HalfLaw)\n"
        + "    registry.add(type('Nameless', (HalfLaw,), {'name': ''}))\n",
        "PluginError: ",
    ),
    "misspelled-hook": (
        LAW + "@hookimpl\ndef plateimpact_regster(registry):\n    registry.add(HalfLaw)\n",
        "HookValidationError: unknown hook 'plateimpact_regster'",
    ),
    "wrong-hook-argument": (
        LAW + "@hookimpl\ndef plateimpact_register(registri):\n    registri.add(HalfLaw)\n",
        "HookValidationError: Plugin ",
    ),
    "core-flag": (
        LAW.replace('flag="--half-strength"', 'flag="--speed"')
        + "@hookimpl\ndef plateimpact_register(registry):\n    registry.add(HalfLaw)\n",
        "PluginError: resistance 'half-law' (pi_broken_core_flag) declares the flag --speed "
        "for plate constant half_strength, but --speed sets the core's impact_speed",
    ),
    "malformed-entry-points": (None, ""),
}
RUN = ["run", "--preset", "2024-T3/3.18", "--speed", "500", "--obliquity", "30"]


def build_distribution(
    root: Path, case: str, source: str | None, group: str = "plateimpact", value: str = ""
) -> tuple[str, str]:
    """A package ``pi_broken_<case>`` and its ``.dist-info`` in ``root``; the distribution's
    name and version as reported, and the entry point as declared."""
    distribution, module = f"plateimpact-broken-{case}", f"pi_broken_{case.replace('-', '_')}"
    package = root / module
    package.mkdir()
    (package / "__init__.py").write_text(source or "")
    info = root / f"{distribution.replace('-', '_')}-0.1.dist-info"
    info.mkdir()
    (info / "METADATA").write_text(f"Metadata-Version: 2.1\nName: {distribution}\nVersion: 0.1\n")
    entry = f"{'report' if value else 'broken'} = {value or module}"
    text = f"[{group}]\n{entry}\n" if source is not None else f"[{group}]\nno equals sign\n"
    (info / "entry_points.txt").write_text(text)
    return f"{distribution} 0.1", entry


@pytest.fixture
def installed(with_third_party, tmp_path, monkeypatch):
    """Install a broken package of each case asked for, beside tests/third_party (at the
    front of the path, or ``last``, after the built-ins); forget its module afterwards,
    so that no other test sees it."""
    before = set(sys.modules)

    def install(case: str, last: bool = False, **kwargs: str) -> tuple[str, str]:
        source = BROKEN[case][0] if case in BROKEN else kwargs.pop("source")
        found = build_distribution(tmp_path, case, source, **kwargs)
        if last:
            monkeypatch.setattr(sys, "path", [*sys.path, str(tmp_path)])
        else:
            monkeypatch.syspath_prepend(str(tmp_path))
        importlib.invalidate_caches()
        pi.default_registry.cache_clear()
        return found

    yield install
    for name in set(sys.modules) - before:
        if name.startswith("pi_broken_"):
            del sys.modules[name]


@pytest.mark.parametrize("case", list(BROKEN))
def test_a_broken_package_is_skipped_and_everything_else_works(case, installed, capsys):
    distribution, entry = installed(case)
    error = BROKEN[case][1]

    assert main(RUN) == 0
    out, err = capsys.readouterr()
    assert out.startswith("2024-T3/3.18: 500 m/s at 30 deg -> perforation\n")
    [warning] = err.splitlines()  # one line, no traceback
    entry_shown = entry if BROKEN[case][0] is not None else "[plateimpact] in entry_points.txt"
    assert warning.startswith(
        f"plateimpact: warning: plug-in package {distribution} failed to load and is skipped "
        f"(entry point {entry_shown}): {error}"
    )

    assert main(["plugins"]) == 0
    out, _ = capsys.readouterr()
    lines = out.splitlines()
    assert lines[0] == "resistance: isotropic-poncelet, poncelet, rate-poncelet"
    assert lines[-1].startswith(f"broken: {distribution} (entry point {entry_shown}): {error}")
    # nothing of it is left: not its law, not the constant the law declares
    assert "half_strength" not in pi.default_registry().plate_constants


def test_the_other_third_party_package_runs_beside_a_broken_one(installed, capsys):
    installed("import")
    assert main([*RUN, "--resistance", "isotropic-poncelet"]) == 0
    assert "-> perforation" in capsys.readouterr().out


def test_choosing_a_plug_in_of_a_broken_package_says_why_it_is_missing(installed, capsys):
    distribution, _ = installed("hook-raises")
    assert main([*RUN, "--resistance", "half-law"]) == 2
    assert capsys.readouterr().err.splitlines()[-1] == (
        f"plateimpact: error: resistance 'half-law' is in plug-in package "
        f"{distribution}, which failed to load: RuntimeError: licence server unreachable"
    )


def test_an_unknown_name_mentions_the_packages_that_failed(installed, capsys):
    distribution, _ = installed("import")
    assert main([*RUN, "--failure", "shatter"]) == 2
    last = capsys.readouterr().err.splitlines()[-1]
    assert last.endswith(
        f"unknown failure 'shatter'; choose from: brittle, hinge, intact, plugging, variable-pstar "
        f"(1 plug-in package failed to load: {distribution})"
    )


def test_a_package_that_clashes_with_the_built_ins_is_the_one_skipped(installed, capsys):
    # Found after the built-ins, its hook is the first pluggy would call; the built-ins
    # register first all the same, so the impostor is refused, not them.
    impostor = LAW + (
        "@hookimpl\ndef plateimpact_register(registry):\n"
        "    registry.add(type('Impostor', (HalfLaw,), {'name': 'poncelet'}))\n"
    )
    distribution, _ = installed("impostor", last=True, source=impostor)
    assert main(RUN) == 0
    out, err = capsys.readouterr()
    assert "-> perforation" in out
    assert f"{distribution} failed to load" in err
    assert "resistance 'poncelet' is registered twice" in err
    assert (
        pi.default_registry()
        .get("resistance", "poncelet")
        .__module__.startswith("plateimpact_plugins")
    )


def test_a_flag_the_command_line_has_already_is_one_line(installed, capsys):
    taken = LAW.replace('flag="--half-strength"', 'flag="--json"') + (
        "@hookimpl\ndef plateimpact_register(registry):\n    registry.add(HalfLaw)\n"
    )
    installed("json-flag", source=taken)
    assert main(RUN) == 2  # run has --json and takes the plug-ins' flags
    assert capsys.readouterr().err.splitlines() == [
        "plateimpact: error: the plug-in resistance 'half-law' (pi_broken_json_flag) declares "
        "the flag --json, which is one of the command line's own options: the plug-in must "
        "declare another"
    ]
    # a command adds only its own options (cli.main): one without the plug-ins' flags
    # still runs, and lists the plug-in to be fixed
    assert main(["plugins"]) == 0
    assert "half-law" in capsys.readouterr().out


def test_the_python_api_warns_and_records_the_package(installed):
    distribution, entry = installed("hook-raises")
    with pytest.warns(pi.PluginLoadWarning, match="plateimpact-broken-hook-raises 0.1"):
        registry = pi.load_registry()
    assert registry.broken == (
        pi.BrokenPackage(
            distribution,
            entry,
            "RuntimeError: licence server unreachable",
            (("resistance", "half-law"),),
        ),
    )
    assert "half-law" not in registry.names("resistance")
    assert "isotropic-poncelet" in registry.names("resistance")


def test_plug_ins_handed_to_load_registry_still_fail_loudly():
    def failing(registry):
        registry.add(pi.default_registry().get("resistance", "poncelet"))
        raise RuntimeError("bug in my hook")

    hook = type("Hooks", (), {"plateimpact_register": staticmethod(pi.hookimpl(failing))})
    with pytest.raises(pi.PluginError, match="failed: RuntimeError: bug in my hook"):
        pi.load_registry(entry_points=False, plugins=[hook])
    with pytest.raises(pi.PluginError, match="cannot be registered"):
        pi.load_registry(entry_points=False, plugins=[hook, hook])


def test_in_a_real_process_the_warning_is_one_line(tmp_path):
    distribution, entry = build_distribution(tmp_path, "import", BROKEN["import"][0])
    path = os.pathsep.join([str(tmp_path), str(THIRD_PARTY), *sys.path])
    done = subprocess.run(
        [sys.executable, "-m", "plateimpact.cli", "plugins", "--details"],
        capture_output=True,
        text=True,
        env={**os.environ, "PYTHONPATH": path},
    )
    assert done.returncode == 0
    assert done.stderr.splitlines() == [
        f"plateimpact: warning: plug-in package {distribution} failed to load and is skipped "
        f"(entry point {entry}): {BROKEN['import'][1]}"
    ]
    assert f"broken: {distribution} (entry point {entry}): {BROKEN['import'][1]}" in done.stdout
    assert "isotropic-poncelet (version" in done.stdout  # the details of the working ones


def test_a_study_collection_that_fails_to_load_is_one_line(installed, tmp_path, capsys):
    distribution, entry = installed(
        "studies",
        source="import plateimpact_missing_dependency\n",
        group="plateimpact.studies",
        value="pi_broken_studies:reproduce",
    )
    assert main(["reproduce", "--out", str(tmp_path / "report")]) == 2
    assert capsys.readouterr().err.splitlines() == [
        f"plateimpact: error: study collection 'report' of {distribution} (entry point "
        f"{entry}) failed to load: ModuleNotFoundError: No module named "
        "'plateimpact_missing_dependency'"
    ]
    assert not (tmp_path / "report").exists()
