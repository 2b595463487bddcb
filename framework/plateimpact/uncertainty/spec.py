"""An uncertainty study's specification, read from JSON (untrusted: every key checked, one
line naming the key for anything wrong)::

    {"preset": "2024-T3/3.18",            (or "plate_file": "plate.json")
     "failure": "plugging",                (optional: the registry's default)
     "at": {"speed_m_s": 400, "obliquity_deg": 0},
     "inputs": {"speed_m_s": {"normal": {"mean": 400, "sd": 15}},
                "pstar_mm": {"uniform": {"low": 2.5, "high": 3.5}}},
     "samples": 20000, "method": "mc", "seed": 7}

``"correlations": [[input, input, rho], ...]`` correlates inputs (a Gaussian copula), and
``"calibration_file": PATH`` adds the inputs and correlations a calibration recorded in the
plate file it wrote (``calibration.uncertainty``). Values are in each input's user unit.
An input with a distribution takes its values from it; the others keep the preset's (or
``at``'s) value. A distribution with more than :data:`MAX_OUTSIDE` of its probability
outside the input's declared range is refused: cut it explicitly (``truncnormal``), never
clamped.
"""

from __future__ import annotations

import os
from pathlib import Path
from typing import Any

import attrs
import numpy as np

from ..base.errors import PlateImpactError
from ..base.untrusted import load_json_file, printable
from ..model.bodies import Plate
from ..registry.plugin_registry import PluginRegistry
from .distributions import KINDS, Distribution
from .inputs import UncertainInput, input_table

#: The methods of sampling: independent draws, scrambled Sobol' points, Latin hypercube.
METHODS = ("mc", "sobol", "lhs")
#: The probability a distribution may put outside its input's range (a sampled value
#: beyond it would still be refused by the scene's own check, never clamped).
MAX_OUTSIDE = 1e-12
#: The most samples a study draws (10⁷ scenes are some minutes on two cores).
MAX_SAMPLES = 10_000_000
KEYS = ("preset", "plate_file", "failure", "at", "inputs", "correlations", "calibration_file",
        "samples", "method", "seed")  # fmt: skip


class UncertaintySpecError(PlateImpactError, ValueError):
    """An uncertainty spec cannot be read or holds an invalid value; the message names
    the file and the key."""


@attrs.frozen
class UncertaintySpec:
    """What to propagate: the plate, the failure model's name (None: the default), the
    nominal ``at`` values and the ``inputs``' distributions [user units], the number of
    samples, the method and the seed; ``source``: where it was read from."""

    plate: Plate
    failure: str | None
    at: dict[str, float]
    inputs: dict[str, Distribution]
    correlations: tuple[tuple[str, str, float], ...] = ()
    samples: int = 10_000
    method: str = "mc"
    seed: int = 0
    source: str = ""

    def describe(self) -> dict[str, Any]:
        """The spec as JSON-ready values (provenance)."""
        return {
            "plate": {"material": self.plate.material, "thickness_m": self.plate.thickness},
            "failure": self.failure,
            "at": dict(self.at),
            "inputs": {name: d.describe() for name, d in self.inputs.items()},
            "correlations": [list(c) for c in self.correlations],
            "samples": self.samples,
            "method": self.method,
            "seed": self.seed,
            "source": self.source,
        }


def _number(value: Any, where: str, error: type[UncertaintySpecError]) -> float:
    if isinstance(value, bool) or not isinstance(value, int | float):
        raise error(f"{where}: a number is needed, got {printable(repr(value), 60)}")
    return float(value)


def _distribution(name: str, given: Any, declared: UncertainInput, what: str) -> Distribution:
    where = f"{what}: inputs.{name}"
    if not isinstance(given, dict) or len(given) != 1:
        kinds = ", ".join(KINDS)
        raise UncertaintySpecError(f"{where}: one distribution is needed, one of {kinds}")
    ((kind, settings),) = given.items()
    if kind not in KINDS:
        raise UncertaintySpecError(
            f"{where}: unknown distribution {printable(kind, 40)!r}; one of {', '.join(KINDS)}"
        )
    if not isinstance(settings, dict):
        raise UncertaintySpecError(f"{where}.{kind}: an object of settings is needed")
    fields = KINDS[kind].settings()
    unknown = sorted(set(settings) - set(fields))
    if unknown or set(fields) - set(settings):
        raise UncertaintySpecError(
            f"{where}.{kind}: takes exactly {', '.join(fields)}"
            + (f" (unknown: {printable(unknown[0], 40)})" if unknown else "")
        )
    values = {
        k: _number(v, f"{where}.{kind}.{k}", UncertaintySpecError) for k, v in settings.items()
    }
    try:
        distribution = KINDS[kind](**values)
    except ValueError as exc:
        raise UncertaintySpecError(f"{where}.{kind}: {exc}") from None
    low, high = declared.user_range
    outside = distribution.mass_outside(low, high)
    if outside > MAX_OUTSIDE:
        raise UncertaintySpecError(
            f"{where}: {outside:.2g} of the {kind} distribution lies outside the input's "
            f"range ({declared.describe_range()}); cut it there with a truncnormal or a "
            "uniform inside it"
        )
    return distribution


def read_spec(
    source: str | os.PathLike[str] | dict[str, Any], registry: PluginRegistry
) -> UncertaintySpec:
    """The spec in the JSON file ``source`` (or a dict of the same form)."""
    from ..registry import presets  # noqa: PLC0415
    from ..storage.plate_file import load_plate_file  # noqa: PLC0415

    if isinstance(source, dict):
        data, what = source, "spec"
    else:
        what = printable(os.fspath(source), 200)
        data = load_json_file(source, UncertaintySpecError)
    if not isinstance(data, dict):
        raise UncertaintySpecError(f"{what}: a JSON object is needed")
    unknown = sorted(set(data) - set(KEYS))
    if unknown:
        raise UncertaintySpecError(
            f"{what}: unknown key {printable(unknown[0], 40)!r}; the keys are {', '.join(KEYS)}"
        )
    if ("preset" in data) == ("plate_file" in data):
        raise UncertaintySpecError(f"{what}: give exactly one of preset and plate_file")
    if "preset" in data:
        if not isinstance(data["preset"], str) or data["preset"] not in presets.PLATES:
            raise UncertaintySpecError(
                f"{what}: preset: one of {', '.join(presets.PLATES)}, got "
                f"{printable(repr(data['preset']), 40)}"
            )
        plate = presets.plate(data["preset"])
    else:
        if not isinstance(data["plate_file"], str):
            raise UncertaintySpecError(f"{what}: plate_file: a path is needed")
        base = Path(os.fspath(source)).parent if not isinstance(source, dict) else Path()
        plate = load_plate_file(base / data["plate_file"], registry)
    failure = data.get("failure")
    if failure is not None and (
        not isinstance(failure, str) or failure not in registry.names("failure")
    ):
        raise UncertaintySpecError(
            f"{what}: failure: one of {', '.join(registry.names('failure'))}, got "
            f"{printable(repr(failure), 40)}"
        )
    table = input_table(registry)
    sections: dict[str, dict[str, Any]] = {}
    for section in ("at", "inputs"):
        given = data.get(section, {})
        if not isinstance(given, dict):
            raise UncertaintySpecError(f"{what}: {section}: an object is needed")
        for name in given:
            if name not in table:
                raise UncertaintySpecError(
                    f"{what}: {section}.{printable(name, 40)}: unknown input; one of "
                    f"{', '.join(table)}"
                )
        sections[section] = given
    at = {k: _number(v, f"{what}: at.{k}", UncertaintySpecError) for k, v in sections["at"].items()}
    for name, value in at.items():
        declared = table[name]
        if not declared.parameter.range.contains(value * declared.parameter.scale):
            raise UncertaintySpecError(
                f"{what}: at.{name}: {value:g} is outside its range ({declared.describe_range()})"
            )
    inputs = {
        name: _distribution(name, given, table[name], what)
        for name, given in sections["inputs"].items()
    }
    correlations = list(_correlation_list(data.get("correlations", []), what))
    if "calibration_file" in data:
        base = Path(os.fspath(source)).parent if not isinstance(source, dict) else Path()
        fitted, fitted_correlations = _calibrated(data["calibration_file"], base, what, table)
        clash = sorted(set(fitted) & set(inputs))
        if clash:
            raise UncertaintySpecError(
                f"{what}: inputs.{clash[0]}: the calibration_file gives it already"
            )
        inputs.update(fitted)
        correlations += fitted_correlations
    for first, second, _ in correlations:
        for name in (first, second):
            if name not in inputs:
                raise UncertaintySpecError(
                    f"{what}: correlations: {printable(name, 40)} has no distribution in inputs"
                )
    check_correlations(correlations, list(inputs), what)
    if "obliquity_deg" not in at and "obliquity_deg" not in inputs:
        raise UncertaintySpecError(f"{what}: obliquity_deg: give it in at or in inputs")
    settings = {"samples": 10_000, "method": "mc", "seed": 0}
    for key in settings:
        if key in data:
            settings[key] = data[key]
    return with_settings(
        UncertaintySpec(plate, failure, at, inputs, tuple(correlations), source=what),
        what,
        samples=settings["samples"],
        method=settings["method"],
        seed=settings["seed"],
    )


def with_settings(
    spec: UncertaintySpec,
    what: str,
    *,
    samples: Any,
    method: Any,
    seed: Any,
    names: tuple[str, str, str] = ("samples", "method", "seed"),
) -> UncertaintySpec:
    """``spec`` with its sampling settings checked (``what``: where they came from: the
    file, or the command line; ``names``: what that place calls them, keys or flags)."""
    if isinstance(samples, bool) or not isinstance(samples, int) or not 2 <= samples <= MAX_SAMPLES:
        raise UncertaintySpecError(f"{what}: {names[0]}: an integer in [2, {MAX_SAMPLES:,}]")
    if method not in METHODS:
        raise UncertaintySpecError(f"{what}: {names[1]}: one of {', '.join(METHODS)}")
    if isinstance(seed, bool) or not isinstance(seed, int) or not 0 <= seed < 2**63:
        raise UncertaintySpecError(f"{what}: {names[2]}: an integer in [0, 2**63)")
    return attrs.evolve(spec, samples=samples, method=method, seed=seed)


def _correlation_list(given: Any, what: str) -> list[tuple[str, str, float]]:
    """``[[name, name, ρ], ...]``, each ρ in (−1, 1)."""
    if not isinstance(given, list):
        raise UncertaintySpecError(f"{what}: correlations: a list of [input, input, rho]")
    out = []
    for k, item in enumerate(given):
        where = f"{what}: correlations[{k}]"
        if not (
            isinstance(item, list) and len(item) == 3 and all(isinstance(n, str) for n in item[:2])
        ):
            raise UncertaintySpecError(f"{where}: [input, input, rho] is needed")
        rho = _number(item[2], where, UncertaintySpecError)
        if not -1.0 < rho < 1.0 or item[0] == item[1]:
            raise UncertaintySpecError(f"{where}: rho in (-1, 1) between two inputs")
        out.append((item[0], item[1], rho))
    return out


def check_correlations(
    correlations: list[tuple[str, str, float]], names: list[str], what: str
) -> None:
    """Each pair once, and a positive definite matrix (a joint distribution exists)."""
    pairs = [frozenset(c[:2]) for c in correlations]
    if len(set(pairs)) != len(pairs):
        raise UncertaintySpecError(f"{what}: correlations: a pair of inputs appears twice")
    if correlations and min(np.linalg.eigvalsh(correlation_matrix(correlations, names))) <= 0:
        raise UncertaintySpecError(
            f"{what}: correlations: no joint distribution has them (the matrix is not positive "
            "definite)"
        )


def correlation_matrix(correlations: Any, names: list[str]) -> np.ndarray:
    """The inputs' correlation matrix, in the order of ``names`` (1 on the diagonal)."""
    matrix = np.eye(len(names))
    for first, second, rho in correlations:
        i, j = names.index(first), names.index(second)
        matrix[i, j] = matrix[j, i] = rho
    return matrix


def _calibrated(
    given: Any, base: Path, what: str, table: dict[str, UncertainInput]
) -> tuple[dict[str, Distribution], list[tuple[str, str, float]]]:
    """The inputs and correlations a calibration recorded in the plate file it wrote
    (its ``calibration.uncertainty`` block, in a spec's own form: the built-in
    calibration's a and b, normal with their standard errors and correlation)."""
    if not isinstance(given, str):
        raise UncertaintySpecError(f"{what}: calibration_file: a path is needed")
    data = load_json_file(base / given, UncertaintySpecError)
    where = f"{what}: calibration_file {printable(given, 80)}"
    block = data.get("calibration") if isinstance(data, dict) else None
    found = block.get("uncertainty") if isinstance(block, dict) else None
    if not isinstance(found, dict) or not isinstance(found.get("inputs"), dict):
        raise UncertaintySpecError(
            f"{where}: no calibration.uncertainty block with inputs (write it with calibrate --out)"
        )
    inputs = {}
    for name, distribution in found["inputs"].items():
        if name not in table:
            raise UncertaintySpecError(f"{where}: {printable(name, 40)}: unknown input")
        inputs[name] = _distribution(name, distribution, table[name], where)
    return inputs, _correlation_list(found.get("correlations", []), where)
