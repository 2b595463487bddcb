"""Bad input is refused with one line naming the parameter and its allowed range."""

from __future__ import annotations

import math

import attrs
import numpy as np
import pytest

import plateimpact as pi
from plateimpact import presets
from plateimpact.units import deg, mm

PLATE = presets.plate("2024-T3/3.18")
SPHERE = presets.DEFAULT_SPHERE


def run(plate: pi.Plate) -> pi.Result:
    return pi.Simulation.from_names().run(pi.Scene(SPHERE, plate, 300.0, 0.0))


@pytest.mark.parametrize(
    ("build", "parameter", "allowed"),
    [
        (lambda: pi.Sphere(radius=0.0, mass=1e-3), "radius", "in [0.001, 1000] mm"),
        (lambda: pi.Sphere(radius=-1 * mm, mass=1e-3), "radius", "in [0.001, 1000] mm"),
        (lambda: pi.Sphere(radius=1 * mm, mass=0.0), "mass", "in [4e-13, 1.1e+08] g"),
        (lambda: pi.Sphere(radius=math.nan, mass=1e-3), "radius", "in [0.001, 1000] mm"),
        (lambda: pi.Sphere.of_density(1 * mm, -5.0), "density", "in [100, 25000] kg/m^3"),
        (lambda: attrs.evolve(PLATE, thickness=0.0), "thickness", "in [0.001, 1000] mm"),
        (lambda: attrs.evolve(PLATE, a=math.nan), "a", "a must be a number"),
        (lambda: attrs.evolve(PLATE, a="strong"), "a", "a must be a number"),
        # A plate constant's range belongs to the plug-in that declares it: checked when a
        # model reads the plate.
        (lambda: run(attrs.evolve(PLATE, a=-1.0)), "a", "in [100000, 1e+11] N/m^2"),
        (lambda: run(attrs.evolve(PLATE, b=-1.0)), "b", "in [0, 100000] kg/m^3"),
        (
            lambda: run(attrs.evolve(PLATE, critical_penetration=0.0)),
            "critical_penetration",
            ">= 1e-06 mm (inf allowed)",
        ),
        (
            lambda: run(attrs.evolve(PLATE, critical_penetration=-math.inf)),
            "critical_penetration",
            ">= 1e-06 mm (inf allowed)",
        ),
        (lambda: run(attrs.evolve(PLATE, failure_angle=0.0)), "failure_angle", "in (0, 90) deg"),
        (
            lambda: run(attrs.evolve(PLATE, failure_angle=90 * deg)),
            "failure_angle",
            "in (0, 90) deg",
        ),
        (lambda: run(pi.Plate("bare", 3 * mm)), "a", "is needed by resistance 'poncelet'"),
        (lambda: pi.Scene(SPHERE, PLATE, 0.0, 0.0), "impact_speed", "in [0.001, 10000] m/s"),
        (lambda: pi.Scene(SPHERE, PLATE, math.inf, 0.0), "impact_speed", "in [0.001, 10000] m/s"),
        (lambda: pi.Scene(SPHERE, PLATE, 100.0, 90 * deg), "impact_obliquity", "in [0, 90) deg"),
        (lambda: pi.Scene(SPHERE, PLATE, 100.0, -1e-9), "impact_obliquity", "in [0, 90) deg"),
        (lambda: pi.Scene(SPHERE, PLATE, 100.0, math.nan), "impact_obliquity", "in [0, 90) deg"),
        (lambda: pi.Scene(SPHERE, PLATE, "fast", 0.0), "impact_speed", "must be a number"),
    ],
)
def test_bad_configuration_names_parameter_and_range(build, parameter, allowed):
    with pytest.raises(pi.ParameterError) as info:
        build()
    assert info.value.parameter == parameter
    message = str(info.value)
    assert message.startswith(parameter) and allowed in message and "\n" not in message


def test_a_never_failing_plate_is_allowed():
    plate = attrs.evolve(PLATE, critical_penetration=math.inf)
    result = pi.Simulation.from_names().run(pi.Scene(SPHERE, plate, 1500.0, 0.0))
    assert not result.plate_failed and result.outcome is pi.Outcome.EMBEDMENT


def test_batch_columns_are_checked_and_the_scene_is_named():
    expected = r"impact_speed must be in \[0.001, 10000\] m/s, got -3 m/s \(scene 1\)"
    with pytest.raises(pi.ParameterError, match=expected):
        pi.SceneBatch.grid(SPHERE, PLATE, np.array([10.0, -3.0]), np.array([0.0]))


def test_unknown_preset_lists_the_presets():
    with pytest.raises(pi.UnknownNameError, match="choose from: 2024-T3/1.27"):
        presets.plate("2024-T3/2.00")


def test_segment_step_must_be_in_range():
    for step in (0.0, -1e-3, 0.5, 1e-9):
        with pytest.raises(pi.ParameterError, match=r"step must be in \[1e-05, 0.1\]"):
            pi.Simulation.from_names(integrator="segment", integrator_settings={"step": step})
