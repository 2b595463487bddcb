"""One unit convention for the Python API (README.md, "The Python API"):
an argument that carries a unit takes SI under a plain name (``obliquities`` [rad],
``speeds`` [m/s], ``radius`` [m]) or says its unit in its name (``obliquities_deg``,
``thickness_mm``) — never degrees under a plain name. This test walks every public
callable of ``import plateimpact as pi`` (functions, classes, their public methods and
the public submodules' names) and fails on an argument named for a quantity that carries
a unit when neither holds: no unit in the name, and its SI unit not stated in brackets
in the docstring of the callable or of its class."""

from __future__ import annotations

import inspect
import re
from collections.abc import Callable, Iterator

import pytest

import plateimpact as pi

#: Suffixes that name a unit (user units and SI alike).
UNIT_SUFFIXES = ("_deg", "_rad", "_mm", "_m", "_m_s", "_g", "_kg", "_s", "_N_m2", "_kg_m3")
#: A word in an argument's name -> the SI unit a plain name means, as a docstring states it.
QUANTITIES = {  # the first word found decides
    "obliquity_rate": ("[rad/s]",),
    "obliquit": ("[rad]",),
    "angle": ("[rad]",),
    "alpha": ("[rad]",),
    "speed": ("[m/s]",),
    "veloc": ("[m/s]",),
    "radius": ("[m]",),
    "thickness": ("[m]",),
    "penetration": ("[m]",),
    "depth": ("[m]",),
    "distance": ("[m/s]", "[m]"),  # a shot's distance to a boundary is a speed
    "mass": ("[kg]",),
    "density": ("[kg/m³]", "[kg/m^3]"),
}
#: Names that carry no unit although they contain a quantity's word: a fraction, a
#: count, a flag or a tolerance whose unit the quantity's own declaration gives.
UNITLESS = {"rest_speed_fraction", "fit_alpha", "alpha_fitted", "speed_samples"}
PUBLIC_SUBMODULES = ("limits", "calibration", "experiment", "v50")


def public_callables() -> Iterator[tuple[str, Callable[..., object], str]]:
    """(label, callable, the docstrings that may state its arguments' units)."""
    seen: set[int] = set()
    spaces = [("", pi, pi.__all__)]
    spaces += [
        (f"{m}.", getattr(pi, m), getattr(getattr(pi, m), "__all__", ())) for m in PUBLIC_SUBMODULES
    ]
    for prefix, space, names in spaces:
        for name in names:
            obj = getattr(space, name)
            if id(obj) in seen or inspect.ismodule(obj) or not callable(obj):
                continue
            seen.add(id(obj))
            label = f"{prefix}{name}"
            class_doc = inspect.getdoc(obj) or "" if inspect.isclass(obj) else ""
            yield label, obj, inspect.getdoc(obj) or ""
            if not inspect.isclass(obj):
                continue
            for method_name, member in vars(obj).items():
                function = getattr(member, "__func__", member)
                if method_name.startswith("_") or not inspect.isfunction(function):
                    continue
                doc = f"{inspect.getdoc(function) or ''}\n{class_doc}"
                yield f"{label}.{method_name}", function, doc


def arguments_of(function: Callable[..., object]) -> list[str]:
    try:
        parameters = inspect.signature(function).parameters
    except (TypeError, ValueError):  # a builtin without a signature
        return []
    return [p for p in parameters if p not in {"self", "cls"}]


def unstated(label: str, function: Callable[..., object], doc: str) -> list[str]:
    """The arguments of ``function`` whose unit neither their name nor ``doc`` states."""
    found = []
    for argument in arguments_of(function):
        if argument in UNITLESS or argument.endswith(UNIT_SUFFIXES):
            continue
        units = next((u for word, u in QUANTITIES.items() if word in argument), None)
        if units is not None and not states(doc, argument, units):
            found.append(f"{label}({argument}): no {' or '.join(units)} after its name")
    return found


def states(doc: str, argument: str, units: tuple[str, ...]) -> bool:
    """Whether ``doc`` names ``argument`` and gives one of ``units`` soon after (within
    :data:`NEAR` characters, on its line or the description under it)."""
    for match in re.finditer(rf"\b{re.escape(argument)}\b", doc):
        after = doc[match.end() : match.end() + NEAR]
        if any(unit in after for unit in units):
            return True
    return False


NEAR = 160  # characters


CALLABLES = list(public_callables())


def test_the_walk_reaches_the_api_that_carries_units():
    """The walk is not vacuous: it reaches the constructors, functions and methods whose
    arguments the convention is about."""
    labels = {label for label, _, _ in CALLABLES}
    assert {"Study.grid", "SceneBatch.grid", "limits.along_speed", "Sphere", "Plate"} <= labels
    assert {"FailureModel.force_change", "fit_v50", "synthetic_oblique_shots"} <= labels


def test_every_public_argument_that_carries_a_unit_states_it():
    wrong = [line for label, obj, doc in CALLABLES for line in unstated(label, obj, doc)]
    assert not wrong, "\n".join(wrong)


@pytest.mark.parametrize(
    ("argument", "doc", "stated"),
    [
        ("obliquities", "angles [deg]", False),  # degrees under a plain name
        ("obliquities", "``obliquities`` [rad]", True),
        ("obliquities", "``obliquities`` are angles" + 200 * " " + "[rad]", False),
        ("obliquities_deg", "", True),
        ("speeds", "", False),
        ("speeds", "``speeds`` (start, stop) [m/s]", True),
        ("rest_speed_fraction", "", True),
    ],
)
def test_the_check_itself_tells_a_stated_unit_from_a_missing_one(argument, doc, stated):
    function = eval(f"lambda {argument}: None")  # noqa: S307 (a fixed test argument)
    assert (unstated("f", function, doc) == []) is stated


def test_degrees_given_as_radians_by_name_are_a_type_error_not_a_silent_run():
    """The defect that led here: ``Study.grid`` took degrees under the plain name
    ``obliquities`` that ``SceneBatch.grid`` takes in radians. Its name now says so, and
    the plain name is not accepted."""
    with pytest.raises(TypeError):
        pi.Study.grid("s", ["2024-T3/3.18"], obliquities=[0.5], speeds=[500.0], variants=[])  # type: ignore[call-arg]
