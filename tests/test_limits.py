"""The boundary finder and the limits it reads (docs/limits.md).

Oracles: a synthetic line whose bands are known exactly (no physics: the finder's
guarantee itself); a failure model that plants a band of known edges; the closed form of
the ballistic limit at normal incidence (docs/calibration.md, section 3); each boundary's
two sides run again one scene at a time; lines along speed and along obliquity read at
their crossings.
"""

from __future__ import annotations

import math
import types
from typing import final

import attrs
import numpy as np
import pytest
from closed_forms import ballistic_limit
from hypothesis import given
from hypothesis import strategies as st

import plateimpact as pi
from plateimpact import limits, presets
from plateimpact.limits import Regime
from plateimpact.limits.bracketing import locate, scan_points
from plateimpact_plugins import CRITICAL_PENETRATION, FAILURE_ANGLE, PlaneSeparation

SPHERE = presets.DEFAULT_SPHERE
R, RSTAR, E, ESTAR, P = (
    Regime(pi.Outcome.RICOCHET, False),
    Regime(pi.Outcome.RICOCHET, True),
    Regime(pi.Outcome.EMBEDMENT, False),
    Regime(pi.Outcome.EMBEDMENT, True),
    Regime(pi.Outcome.PERFORATION, True),
)


@pytest.fixture(scope="module")
def simulation() -> pi.Simulation:
    return pi.Simulation.from_names()


def regime_of(simulation: pi.Simulation, plate: pi.Plate, speed: float, obliquity: float):
    result = simulation.run(pi.Scene(SPHERE, plate, speed, obliquity))
    return Regime(result.outcome, result.plate_failed)


# -- the finder's guarantee, on lines whose bands are known exactly ----------------------


@given(
    span=st.floats(0.5, 500.0),
    resolution=st.floats(0.01, 10.0),
)
def test_the_scan_leaves_no_gap_wider_than_the_resolution(span, resolution):
    _, k, x = scan_points(np.array([3.0]), np.array([3.0 + span]), resolution)
    assert x[0] == 3.0 and x[-1] == 3.0 + span
    assert np.all(np.diff(x) > 0) and np.diff(x).max() <= resolution * (1 + 1e-9)


@given(
    edges=st.lists(st.floats(0.0, 100.0), min_size=1, max_size=12, unique=True),
    resolution=st.sampled_from([0.3, 1.0, 2.5]),
    tolerance=st.sampled_from([1e-3, 0.01, 0.2]),
)
def test_every_band_as_wide_as_the_resolution_is_found_and_bracketed(edges, resolution, tolerance):
    """Bands between sorted ``edges`` (codes cycling through 3 values, so neighbours
    differ): every band at least ``resolution`` wide is seen (a found band of its code
    overlaps it), an edge between two such bands is bracketed, every found boundary is a
    true change bracketed within the tolerance, and the brackets chain."""
    tolerance = min(tolerance, resolution)
    cuts = np.sort(np.asarray(edges))

    def code(x: np.ndarray) -> np.ndarray:
        return np.searchsorted(cuts, x, side="right") % 3

    found = locate(lambda line, x: code(x), np.array([0.0]), np.array([100.0]), resolution,
                   tolerance)  # fmt: skip
    assert np.all(found.high - found.low <= tolerance * (1 + 1e-9))
    np.testing.assert_array_equal(found.below, code(found.low))
    np.testing.assert_array_equal(found.above, code(found.high))
    assert np.all(found.above[:-1] == found.below[1:])  # each ends where the next begins
    assert found.below.size == 0 or found.below[0] == found.first[0]
    seen_edges = np.concatenate([[0.0], 0.5 * (found.low + found.high), [100.0]])
    seen_codes = np.concatenate([found.first, found.above])
    true_edges = np.concatenate([[0.0], cuts[(cuts > 0) & (cuts < 100)], [100.0]])
    wide = np.diff(true_edges) >= resolution
    for k in np.flatnonzero(wide):
        lo, hi = true_edges[k], true_edges[k + 1]
        mine = (seen_codes == code(np.array([lo]))[0]) & (seen_edges[:-1] < hi)
        assert np.any(mine & (seen_edges[1:] > lo)), (lo, hi)
        if k > 0 and wide[k - 1]:
            assert np.any((found.low < lo) & (lo <= found.high)), lo


# -- a band planted by a plug-in ----------------------------------------------------------


@final
@attrs.frozen
class PlantedBand(PlaneSeparation):
    """Plugging, except that for impact speeds in [band_start, band_end) the plate never
    fails: a band of intact embedment planted in the perforation range."""

    name = "planted-band"
    plate_constants = (CRITICAL_PENETRATION, FAILURE_ANGLE)

    band_start: float = pi.Parameter("band_start", "", "m/s", default=700.0).field()
    band_end: float = pi.Parameter("band_end", "", "m/s", default=700.5).field()

    def onset_penetration(self, batch: pi.SceneBatch) -> np.ndarray:
        inside = (batch.impact_speed >= self.band_start) & (batch.impact_speed < self.band_end)
        return np.where(inside, np.inf, batch.critical_penetration)


@pytest.fixture(scope="module")
def planted_registry() -> pi.PluginRegistry:
    @pi.hookimpl
    def plateimpact_register(registry: pi.PluginRegistry) -> None:
        registry.add(PlantedBand)

    return pi.load_registry(
        plugins=[types.SimpleNamespace(plateimpact_register=plateimpact_register)]
    )


@pytest.mark.parametrize("band_start", [700.0, 700.37, 811.91])
def test_a_half_metre_per_second_band_planted_by_a_plug_in_is_found(band_start, planted_registry):
    simulation = pi.Simulation.from_names(
        failure="planted-band",
        failure_settings={"band_start": band_start, "band_end": band_start + 0.5},
        registry=planted_registry,
    )
    plate = presets.plate("2024-T3/3.18")
    found = limits.along_speed(simulation, SPHERE, plate, [0.0], (300.0, 1000.0), resolution=0.5)
    (line,) = found.lines
    assert [band.regime for band in line.bands] == [E, ESTAR, P, E, P]
    into, out_of = line.boundaries[2], line.boundaries[3]
    assert into.low < band_start <= into.high and out_of.low < band_start + 0.5 <= out_of.high
    assert into.high - into.low <= 0.01 and out_of.high - out_of.low <= 0.01


# -- the model's own limits ---------------------------------------------------------------


@pytest.mark.parametrize("rest_speed_fraction", [0.01, 1e-6])
@pytest.mark.parametrize("name", presets.PLATES)
def test_the_ballistic_limit_at_normal_incidence_is_the_closed_form(name, rest_speed_fraction):
    """a + b Vr² = (a + b Vs²) R², R² = exp(−2bW/m) (eq 40's form, exact for the model at
    θ = 0): tests/closed_forms.py."""
    plate = presets.plate(name)
    f = rest_speed_fraction
    closed_form = ballistic_limit(plate, SPHERE, f)
    simulation = pi.Simulation.from_names(rest_speed_fraction=f)
    found = limits.along_speed(simulation, SPHERE, plate, [0.0], (50.0, 2000.0))
    (line,) = found.lines
    assert line.bands[-2].regime == ESTAR  # the plate fails below the ballistic limit
    assert line.ballistic_limit == pytest.approx(closed_form, abs=found.tolerance / 2 + 1e-6)


@pytest.mark.parametrize("name", ["2024-T3/6.35", "6061-T6/9.53"])
def test_each_boundary_has_its_two_regimes_on_its_two_sides(name, simulation):
    plate = presets.plate(name)
    found = limits.along_speed(simulation, SPHERE, plate, np.radians([45.0, 60.0]))
    for line in found.lines:
        assert len(line.boundaries) >= 3
        for boundary in line.boundaries:
            assert 0 < boundary.high - boundary.low <= found.tolerance
            assert regime_of(simulation, plate, boundary.low, line.fixed) == boundary.below
            assert regime_of(simulation, plate, boundary.high, line.fixed) == boundary.above
        bands = line.bands
        assert bands[0].start == 50.0 and bands[-1].end == 2000.0
        assert all(
            x.end == y.start and x.regime != y.regime
            for x, y in zip(bands[:-1], bands[1:], strict=True)
        )


def test_the_thin_plate_at_45_degrees_has_its_four_bands_in_order(simulation):
    """Issue 16: ricochet, ricochet after failure (about 20 m/s wide), embedment (about
    2.5 m/s), perforation."""
    found = limits.along_speed(simulation, SPHERE, presets.plate("2024-T3/1.27"), [math.pi / 4])
    (line,) = found.lines
    assert [band.regime for band in line.bands] == [R, RSTAR, ESTAR, P]
    assert 10.0 < line.bands[1].width < 30.0 and 1.0 < line.bands[2].width < 5.0
    assert line.ricochet_limit == line.bands[1].end
    assert line.lowest_perforation == line.ballistic_limit  # one perforation band
    assert line.ballistic_limit == line.bands[3].start


def test_limits_along_speed_and_along_obliquity_agree_where_the_lines_cross(simulation):
    plate = presets.plate("2024-T3/3.18")
    obliquities = np.radians([0.0, 20.0, 45.0, 60.0])
    speeds = np.array([300.0, 450.0, 500.0, 700.0])
    by_speed = limits.along_speed(simulation, SPHERE, plate, obliquities, (100.0, 900.0))
    by_obliquity = limits.along_obliquity(
        simulation, SPHERE, plate, speeds, (0.0, math.radians(80))
    )

    def regime_at(line: limits.LimitLine, x: float) -> Regime | None:
        """The band holding x; None within the tolerance of a boundary."""
        if any(abs(x - b.at) <= 0.5 * (b.high - b.low) + 1e-12 for b in line.boundaries):
            return None
        return next(band.regime for band in line.bands if band.start <= x <= band.end)

    compared = 0
    for s_line in by_speed.lines:
        for o_line in by_obliquity.lines:
            a = regime_at(s_line, o_line.fixed)
            b = regime_at(o_line, s_line.fixed)
            if a is not None and b is not None:
                assert a == b, (math.degrees(s_line.fixed), o_line.fixed)
                compared += 1
    assert compared >= 14


def test_the_critical_ricochet_obliquity_ends_the_last_non_ricochet_band(simulation):
    plate = presets.plate("2024-T3/3.18")
    found = limits.along_obliquity(simulation, SPHERE, plate, [600.0])
    (line,) = found.lines
    critical = line.critical_ricochet_obliquity
    assert critical is not None and line.bands[-1].regime.outcome is pi.Outcome.RICOCHET
    assert regime_of(simulation, plate, 600.0, critical - found.tolerance).outcome is not (
        pi.Outcome.RICOCHET
    )
    for obliquity in np.linspace(critical + found.tolerance, math.radians(89), 7):
        assert regime_of(simulation, plate, 600.0, obliquity).outcome is pi.Outcome.RICOCHET


# -- named limits on lines built by hand -------------------------------------------------


def line_of(first: Regime, *boundaries: tuple[float, Regime]) -> limits.LimitLine:
    made, below = [], first
    for at, above in boundaries:
        made.append(limits.Boundary(at - 0.005, at + 0.005, below, above))
        below = above
    return limits.LimitLine(limits.SPEED, 0.0, 50.0, 2000.0, tuple(made), first)


def test_named_limits_say_none_where_the_range_holds_no_boundary():
    only_perforation = line_of(P)
    assert only_perforation.ballistic_limit is None and only_perforation.ricochet_limit is None
    no_perforation = line_of(R, (300.0, E))
    assert no_perforation.ballistic_limit is None and no_perforation.ricochet_limit == 300.0
    # perforation, then a planted embedment band, then perforation again
    twice = line_of(E, (400.0, P), (700.0, E), (700.5, P))
    assert twice.lowest_perforation == 400.0 and twice.ballistic_limit == 700.5
    always_ricochets = line_of(R, (300.0, RSTAR))
    assert always_ricochets.ricochet_limit is None


@pytest.mark.parametrize(
    ("call", "parameter"),
    [
        (lambda s, p: limits.along_speed(s, SPHERE, p, [0.0], (500.0, 500.0)), "speeds"),
        (lambda s, p: limits.along_speed(s, SPHERE, p, [0.0], (900.0, 500.0)), "speeds"),
        (lambda s, p: limits.along_speed(s, SPHERE, p, [0.0], tolerance=0.0), "tolerance"),
        (lambda s, p: limits.along_speed(s, SPHERE, p, [0.0], tolerance=math.nan), "tolerance"),
        (lambda s, p: limits.along_speed(s, SPHERE, p, [0.0], tolerance=5000.0), "tolerance"),
        (lambda s, p: limits.along_speed(s, SPHERE, p, [0.0], resolution=0.001), "resolution"),
        (lambda s, p: limits.along_speed(s, SPHERE, p, [0.0] * 600, resolution=0.01), "resolution"),
        (lambda s, p: limits.along_speed(s, SPHERE, p, []), "obliquities"),
        (lambda s, p: limits.along_speed(s, SPHERE, p, [math.pi / 2]), "impact_obliquity"),
        (lambda s, p: limits.along_obliquity(s, SPHERE, p, [600], (0, 2)), "impact_obliquity"),
        (lambda s, p: limits.along_obliquity(s, SPHERE, p, [1e5]), "impact_speed"),
    ],
)  # fmt: skip
def test_bad_requests_are_parameter_errors_before_any_scene_runs(call, parameter, simulation):
    with pytest.raises(pi.ParameterError) as info:
        call(simulation, presets.plate("2024-T3/3.18"))
    assert info.value.parameter == parameter


# -- the outcome map ----------------------------------------------------------------------


def test_the_outcome_map_is_its_scenes_and_its_rows_are_the_limits(simulation):
    from plateimpact.limits.maps import outcome_map

    plate = presets.plate("2024-T3/3.18")
    rows = np.radians([0.0, 30.0, 60.0])
    found = outcome_map(simulation, SPHERE, plate, (100.0, 1000.0), 10, rows)
    np.testing.assert_allclose(found.speeds, np.linspace(100.0, 1000.0, 10), rtol=1e-15)
    assert found.shape == (3, 10)
    for i, j in [(0, 0), (1, 4), (2, 7), (2, 9)]:
        scene = pi.Scene(SPHERE, plate, found.speeds[j], rows[i])
        alone = simulation.run(scene)
        assert found.regime[i, j] == Regime(alone.outcome, alone.plate_failed).code
        assert found.exit_speed[i, j] == alone.exit_speed  # a scene ignores its batch
    spacing = found.speeds[1] - found.speeds[0]
    assert found.limits.resolution == pytest.approx(spacing)
    for row, line in zip(found.regime, found.limits.lines, strict=True):
        # each row's regimes are the bands of its line at the grid's speeds
        for code, speed in zip(row, found.speeds, strict=True):
            near = any(b.low <= speed <= b.high for b in line.boundaries)
            band = next(b for b in line.bands if b.start <= speed <= b.end)
            assert near or band.regime.code == code
    curves = found.boundary_curves()
    assert sum(xs.size for _, _, xs, _ in curves) == sum(
        len(line.boundaries) for line in found.limits.lines
    )


def test_maps_found_together_are_the_maps_found_alone(simulation):
    from plateimpact.limits.maps import outcome_map, outcome_maps

    names = ["2024-T3/1.27", "SAE1010/1.47"]
    grid = ((100.0, 900.0), 9, np.radians([0.0, 40.0]))
    together = outcome_maps(simulation, SPHERE, [presets.plate(n) for n in names], *grid)
    for name, found in zip(names, together, strict=True):
        alone = outcome_map(simulation, SPHERE, presets.plate(name), *grid)
        np.testing.assert_array_equal(found.regime, alone.regime)
        np.testing.assert_array_equal(found.exit_speed, alone.exit_speed)
        assert found.limits.plate == presets.plate(name)
        for a, b in zip(found.limits.lines, alone.limits.lines, strict=True):
            assert a.boundaries == b.boundaries
