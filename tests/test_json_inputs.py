"""JSON from someone else at the command line (``run --inputs``, ``--plate-file``,
``--set SLOT.NAME=VALUE``) and in an archive's variant records: deep nesting, an integer
of hundreds of digits, a key given twice, NaN, and a value of the wrong type are each
one line naming the key (and the range, for a number), exit code 2; never a traceback,
an internal error, or the last of two keys silently winning."""

from __future__ import annotations

import json
from pathlib import Path

import attrs
import pytest
from test_output_files import assert_one_line, run_cli

import plateimpact as pi
from plateimpact import presets
from plateimpact.base.errors import ParameterError
from plateimpact.storage.plate_file import plate_to_dict
from plateimpact_plugins.plugging import Plugging

DEEP = "[" * 100_000 + "]" * 100_000
HUGE = "1" * 401


@pytest.fixture(scope="module")
def record() -> str:
    """A ``run --json`` output's text, whose ``inputs`` ``run --inputs`` reads."""
    code, out, _ = run_cli(["run", "--preset", "2024-T3/3.18", "--speed", "500",
                            "--obliquity", "45", "--json"])  # fmt: skip
    assert code == 0
    return json.dumps(json.loads(out)["inputs"])


def with_speed(record: str, literal: str) -> str:
    """``record`` with the impact speed's number replaced by the JSON text ``literal``."""
    assert '"impact_speed_m_s": 500.0' in record
    return record.replace('"impact_speed_m_s": 500.0', f'"impact_speed_m_s": {literal}', 1)


@pytest.mark.parametrize(
    ("literal", "named"),
    [
        (HUGE, ["impact_speed_m_s", "401 digits", "at most 18"]),
        ("1e400", ["impact_speed_m_s", "[0.001, 10000] m/s", "inf"]),
        ("-1e400", ["impact_speed_m_s", "[0.001, 10000] m/s"]),
        ("true", ["impact_speed_m_s", "must be a number", "[0.001, 10000] m/s", "true"]),
        ('"500"', ["impact_speed_m_s", "must be a number", "the string"]),
        ("[500]", ["impact_speed_m_s", "must be a number", "an array"]),
        ("{}", ["impact_speed_m_s", "must be a number", "an object"]),
        ("null", ["impact_speed_m_s", "must be a number"]),
        ("NaN", ["NaN"]),
        (DEEP, ["nested more than"]),
        ('500.0, "impact_speed_m_s": 600.0', ["impact_speed_m_s", "appears twice"]),
    ],
)
def test_run_inputs_with_a_bad_speed_is_one_line_naming_the_key(record, tmp_path, literal, named):
    path = tmp_path / "run.json"
    path.write_text(with_speed(record, literal))
    code, out, err = run_cli(["run", "--inputs", str(path)])
    assert_one_line(code, err, str(path), *named)
    assert out == ""


@pytest.mark.parametrize(
    ("text", "named"),
    [
        (DEEP, ["nested more than"]),
        ('{"a":' * 50 + "1" + "}" * 50, ["nested more than"]),
        ("x" * 10, ["not valid JSON"]),
        ('{"inputs": {"format": "plateimpact-inputs-1", "sphere": []}}', ["sphere", "an array"]),
    ],
)
def test_run_inputs_that_is_no_record_is_one_line(tmp_path, text, named):
    path = tmp_path / "run.json"
    path.write_text(text)
    assert_one_line(*run_cli(["run", "--inputs", str(path)])[::2], *named)


def plate_file(tmp_path: Path, text: str) -> list[str]:
    path = tmp_path / "plate.json"
    path.write_text(text)
    return ["run", "--plate-file", str(path), "--speed", "500", "--obliquity", "45"]


def plate_text() -> str:
    return json.dumps(plate_to_dict(presets.plate("2024-T3/3.18"), registry=pi.default_registry()))


def test_a_plate_file_with_a_key_twice_is_refused_not_the_last_winning(tmp_path):
    text = plate_text().replace('"a_N_m2": ', '"a_N_m2": 5e8, "a_N_m2": ', 1)
    assert json.loads(text)["a_N_m2"] == 1.01e9  # what json would have read, silently
    code, out, err = run_cli(plate_file(tmp_path, text))
    assert_one_line(code, err, "a_N_m2", "appears twice")
    assert out == ""


@pytest.mark.parametrize(
    ("key", "literal", "named"),
    [
        ("a_N_m2", HUGE, ["a_N_m2", "401 digits"]),
        ("a_N_m2", "1e400", ["a_N_m2", "[100000, 1e+11] N/m^2"]),
        ("pstar_mm", "true", ["pstar_mm", "must be a number", "true"]),
        ("thickness_mm", '"3.18"', ["thickness_mm", "must be a number", "the string"]),
        ("thickness_mm", "1e400", ["thickness_mm"]),
        ("b_kg_m3", DEEP, ["nested more than"]),
        ("alpha_deg", "NaN", ["NaN"]),
    ],
)
def test_a_plate_file_with_a_bad_number_is_one_line_naming_the_key(tmp_path, key, literal, named):
    record = plate_to_dict(presets.plate("2024-T3/3.18"), registry=pi.default_registry())
    text = json.dumps(record).replace(f'"{key}": {json.dumps(record[key])}', f'"{key}": {literal}')
    assert text != json.dumps(record)
    code, out, err = run_cli(plate_file(tmp_path, text))
    assert_one_line(code, err, *named)


# -- --set SLOT.NAME=VALUE of a setting no declaration describes (a JSON literal) ---------


@attrs.frozen
class TunedPlugging(Plugging):
    """Plugging with a setting of its own that no declaration describes: ``--set`` reads
    it as a JSON literal (parameters.json_literal)."""

    name = "tuned-plugging"
    note: object = None


@pytest.fixture
def tuned(monkeypatch):
    """The command line with ``tuned-plugging`` registered beside the built-ins."""
    import types

    @pi.hookimpl
    def plateimpact_register(registry: pi.PluginRegistry) -> None:
        registry.add(TunedPlugging)

    registry = pi.load_registry(
        plugins=[types.SimpleNamespace(plateimpact_register=plateimpact_register)]
    )
    # the command line's one registry (cli.main loads it where none is given)
    monkeypatch.setattr("plateimpact.registry.plugin_registry.default_registry", lambda: registry)
    return ["run", "--preset", "2024-T3/3.18", "--speed", "500", "--obliquity", "45",
            "--failure", "tuned-plugging"]  # fmt: skip


@pytest.mark.parametrize(
    ("value", "named"),
    [
        (DEEP, ["--set failure.note", "nested more than"]),
        ('{"a": 1, "a": 2}', ["--set failure.note", "appears twice"]),
        (f"[{HUGE}]", ["--set failure.note", "401 digits"]),
        ("[NaN]", ["--set failure.note", "NaN"]),
        ("[1, 2", ["--set failure.note", "not valid JSON"]),
    ],
)
def test_a_set_json_literal_beyond_bounds_is_one_line_naming_the_flag(tuned, value, named):
    code, out, err = run_cli([*tuned, "--set", f"failure.note={value}"])
    assert_one_line(code, err, *named)


@pytest.mark.parametrize(
    ("value", "setting"),
    [
        ("RK23", "RK23"),
        ('{"a": [1, 2.5]}', {"a": [1, 2.5]}),
        ("12", 12),
        ("true", True),
        ('"[1, 2]"', "[1, 2]"),  # a JSON string is that string, not parsed again
    ],
)
def test_a_set_json_literal_within_bounds_or_plain_text_is_read(tuned, value, setting):
    code, out, err = run_cli([*tuned, "--set", f"failure.note={value}", "--json"])
    assert code == 0 and err == "", err
    assert json.loads(out)["model"]["failure_settings"]["note"] == setting


@pytest.mark.parametrize(
    ("value", "words"),
    [(DEEP, "nested"), ('{"a": 1, "a": 2}', "appears twice"), ("[NaN]", "NaN")],
)
def test_an_undeclared_settings_text_parsed_in_python_is_a_parameter_error(value, words):
    declared = TunedPlugging.setting_declarations()["note"]
    with pytest.raises(ParameterError, match=words):
        declared.parse(value)


# -- an archive's variant record -----------------------------------------------------------


@pytest.mark.parametrize(
    ("text", "words"),
    [
        (DEEP, "nested more than"),
        ('{"name": "a", "name": "b"}', "appears twice"),
        ('{"name": "a", "x": 1}', "unknown key 'x'"),
        ('{"name": "a", "failure": 1}', "failure must be a plug-in name"),
        ('{"name": "a", "rest_speed_fraction": NaN}', "NaN"),
        ('{"name": "a", "failure_settings": [1]}', "must be a mapping"),
        ("[1]", "expected a JSON object"),
        ("{", "not valid JSON"),
    ],
)
def test_a_variant_record_from_an_archive_is_read_or_one_line(text, words):
    with pytest.raises(ParameterError, match=words) as caught:
        pi.Variant.from_json(text)
    assert "\n" not in str(caught.value)


def test_a_variant_record_reads_back_as_written():
    variant = pi.Variant("v", failure="variable-pstar", integrator_settings={"rtol": 1e-9})
    assert pi.Variant.from_json(variant.to_json()) == variant
