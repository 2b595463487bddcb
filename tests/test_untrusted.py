"""JSON from someone else within bounds, and file text made inert for a terminal
(plateimpact.base.untrusted)."""

from __future__ import annotations

import json
import math

import pytest

from plateimpact.base.errors import PlateFileError
from plateimpact.base.untrusted import MAX_DEPTH, load_json, printable


def test_plain_json_reads_as_json_does():
    text = '{"a": [1, 2.5, "x", null, true], "b": {"c": -3}, "p": Infinity}'
    value = load_json(text, "f.json", PlateFileError)
    assert value == json.loads(text)
    assert math.isinf(value["p"])


@pytest.mark.parametrize(
    ("text", "words"),
    [
        ("[" * 100_000 + "]" * 100_000, "nested more than"),
        ("[" * (MAX_DEPTH + 1) + "]" * (MAX_DEPTH + 1), "nested more than"),
        ('{"a": 1, "a": 2}', "appears twice"),
        ('{"x": {"a": 1, "a": 1}}', "appears twice"),
        ("1" * 401, "integer of 401 digits"),
        ('{"a": NaN}', "NaN"),
        ('{"a": ', "not valid JSON"),
        (b"\xff\xfe{}", "not UTF-8"),
    ],
)
def test_malformed_json_is_one_line_of_the_callers_error(text, words):
    with pytest.raises(PlateFileError) as caught:
        load_json(text, "plate.json", PlateFileError)
    message = str(caught.value)
    assert message.startswith("plate.json: ") and words in message
    assert "\n" not in message


def test_nesting_inside_strings_is_not_counted():
    text = json.dumps({"note": "[" * 1000})
    assert load_json(text, "f") == {"note": "[" * 1000}


def test_oversized_json_is_refused_before_parsing():
    with pytest.raises(PlateFileError, match="more than the 10 read"):
        load_json(b"[" + b"1," * 20 + b"1]", "f", PlateFileError, max_bytes=10)


@pytest.mark.parametrize(
    "text",
    [
        "run\x1b[2J\x1b]0;owned\x07",
        "a\nplateimpact: error: forged",
        "cr\rover",
        "bidi \u202eevil",
        "nul\x00",
        "del\x7f",
    ],
)
def test_printable_leaves_nothing_a_terminal_acts_on(text):
    out = printable(text)
    assert out.isprintable()
    assert "\n" not in out and "\x1b" not in out and "\r" not in out


def test_printable_keeps_ordinary_text_and_cuts_long_text():
    assert printable("2024-T3/3.18 at 60° — P* 3 mm") == "2024-T3/3.18 at 60° — P* 3 mm"
    assert printable("x" * 50, limit=10) == "xxxxxxx..."
