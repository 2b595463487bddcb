"""The sampled ballistic and ricochet limits, the Sobol' indices of the ballistic limit,
and what an uncertainty study keeps in its archive (docs/uncertainty.md).

Oracles: direct Monte Carlo at a speed (each sample run there ricochets exactly when its
sampled ricochet limit lies above it, to the finder's tolerance); the closed-form
ballistic limit at normal incidence (tests/closed_forms.py), whose variance shares to two
independent inputs follow by quadrature because it factors as sqrt(a) g(P*); the model's
own invariants (the same search alone, together or on a pool gives the same bits)."""

from __future__ import annotations

import contextlib
import io
import json
import math
import sys
from concurrent.futures import ProcessPoolExecutor
from pathlib import Path

import attrs
import numpy as np
import pytest
import xarray
from closed_forms import ballistic_limit
from old_records import to_old_layout
from test_limits_archive import record_file
from test_output_files import assert_one_line, run_cli
from test_progress import Pipe, Terminal, ticking
from test_record_files import exported

import plateimpact as pi
from plateimpact import presets
from plateimpact.cli import main
from plateimpact.limits.lines import SPEED, Boundary, LimitLine
from plateimpact.limits.regimes import Regime
from plateimpact.model.impact import REST_SPEED_FRACTION
from plateimpact.storage import append as appending
from plateimpact.uncertainty import propagate, read_spec
from plateimpact.uncertainty.archived import (
    KIND_LIMITS,
    indices_to_record,
    limits_to_record,
    map_to_record,
    read_stored,
    record_name,
)
from plateimpact.uncertainty.curves import outcome_grid
from plateimpact.uncertainty.kept import SEARCH, kept_limits
from plateimpact.uncertainty.limit_search import named_limits
from plateimpact.uncertainty.limits import sampled_limits, sampled_limits_at
from plateimpact.uncertainty.sensitivity import ballistic_limit_indices, perforation_indices
from plateimpact.uncertainty.spec import UncertaintySpecError

PRESET = "2024-T3/3.18"
SHOTS = str(Path(__file__).resolve().parents[1] / "studies/data/gonogo_SAE1010_1.47mm.csv")


@pytest.fixture(scope="module")
def registry():
    return pi.default_registry()


def oblique(samples: int, seed: int = 6, obliquity: float = 30.0) -> dict:
    """P* and a uncertain on the 3.18-mm plate: at 30 deg its ricochet limit (the end of
    the ricochets after failure) moves with both."""
    return {
        "preset": PRESET,
        "failure": "plugging",
        "at": {"obliquity_deg": obliquity},
        "inputs": {
            "pstar_mm": {"uniform": {"low": 2.5, "high": 3.5}},
            "a_N_m2": {"normal": {"mean": 1.01e9, "sd": 5e7}},
        },
        "samples": samples,
        "seed": seed,
    }


@pytest.fixture(scope="module")
def at_30(registry):
    return sampled_limits(read_spec(oblique(60), registry), registry, 30.0)


@pytest.mark.parametrize("speed", [385.0, 410.0, 435.0])
def test_the_ricochet_curve_from_sampled_limits_is_per_speed_monte_carlo(registry, at_30, speed):
    """P(ricochet | V) = P(V_rl > V): running each sample at V ricochets exactly when its
    ricochet limit lies above V (the same seed draws the same samples), apart from a
    limit within the finder's tolerance of V; the two estimates lie in each other's
    intervals. The same for perforation and the ballistic limit."""
    given = oblique(60)
    given["at"]["speed_m_s"] = speed
    direct = propagate(read_spec(given, registry), registry)
    assert np.array_equal(direct.inputs["pstar_mm"], at_30.inputs["pstar_mm"])
    outcome = direct.result.outcome
    for limit, ended, above in (
        (at_30.ricochet, outcome == pi.Outcome.RICOCHET, True),
        (at_30.ballistic, outcome == pi.Outcome.PERFORATION, False),
    ):
        close = np.abs(limit - speed) <= at_30.tolerance
        counted = (limit > speed) if above else (limit < speed)
        assert np.array_equal(ended[~close], counted[~close])
    probability, low, high = at_30.ricochet_curve(np.array([speed]))
    assert probability[0] == np.mean(at_30.ricochet > speed)
    assert at_30.perforation_curve(np.array([speed]))[0][0] == np.mean(at_30.ballistic < speed)
    assert low[0] <= direct.probabilities()["ricochet"] <= high[0]
    direct_low, direct_high = direct.intervals()["ricochet"]
    assert direct_low <= probability[0] <= direct_high
    assert at_30.ricochet_gaps == 0 and at_30.perforation_gaps == 0


def test_the_ricochet_limit_lies_below_the_ballistic_limit_and_both_are_found(at_30):
    """At 30 deg every sample ricochets up to its ricochet limit, then embeds, then
    perforates above its ballistic limit (docs/limits.md)."""
    assert np.all(np.isfinite(at_30.ricochet)) and np.all(np.isfinite(at_30.ballistic))
    assert np.all(at_30.ricochet < at_30.ballistic)
    report = at_30.report("ricochet")
    assert report["within_range"] == 60 and report["v10_m_s"] < report["v90_m_s"]


def line(*bands: tuple[pi.Outcome, bool, float]) -> LimitLine:
    """A line along speed over 50-2000 m/s whose regimes change at the given speeds
    (each band: outcome, plate failed, where it ends), brackets 0.1 m/s wide."""
    regimes = [Regime(o, failed) for o, failed, _ in bands]
    boundaries = tuple(
        Boundary(end - 0.05, end + 0.05, below, above)
        for (_, _, end), below, above in zip(bands[:-1], regimes[:-1], regimes[1:], strict=True)
    )
    return LimitLine(SPEED, 0.5, 50.0, 2000.0, boundaries, regimes[0])


R, E, P = pi.Outcome.RICOCHET, pi.Outcome.EMBEDMENT, pi.Outcome.PERFORATION


@pytest.mark.parametrize(
    "bands, expected",
    [
        (((R, False, 300), (E, True, 400), (P, True, 2000)), (400, 300, False, False)),
        (((E, False, 400), (P, True, 2000)), (400, -math.inf, False, False)),
        (((R, False, 2000),), (math.inf, math.inf, False, False)),
        (((P, True, 2000),), (-math.inf, -math.inf, False, False)),
        (((E, False, 100), (R, False, 300), (E, False, 400), (P, True, 2000)),
         (400, 300, False, True)),  # a ricochet band above an embedment one
        (((R, False, 200), (P, True, 300), (E, True, 500), (P, True, 2000)),
         (500, 200, True, False)),  # a perforation band below an embedment one
    ],
)  # fmt: skip
def test_each_lines_limits_are_those_plateimpact_limits_names(bands, expected):
    """Ballistic and ricochet limits as LimitLine names them (docs/limits.md), ±inf for
    none in the range on the side the curve needs, and the gaps the curve would miss."""
    found = named_limits(line(*bands))
    assert found[:2] == pytest.approx(expected[:2], abs=0.05) and found[2:] == expected[2:]


def test_limits_at_several_obliquities_are_each_obliquitys_alone(registry):
    """One search over several obliquities gives each obliquity's limits bit for bit
    (a line's scenes do not depend on the batch they run in, so a dozen samples show it
    as well as many)."""
    spec = read_spec(oblique(12), registry)
    both = sampled_limits_at(spec, registry, [0.0, 30.0])
    alone = sampled_limits(spec, registry, 30.0)
    assert np.all(np.isfinite(alone.ricochet))  # ricochet limits to compare at 30 deg
    assert np.array_equal(both[1].ballistic, alone.ballistic)
    assert np.array_equal(both[1].ricochet, alone.ricochet)
    alone = sampled_limits(spec, registry, 0.0)
    assert np.array_equal(both[0].ballistic, alone.ballistic)


def test_where_no_sample_ricochets_it_is_said_not_a_number(tmp_path):
    """At normal incidence the sphere never ricochets; at 80 deg it ricochets at every
    speed of the range and never perforates: each said in words and counts, the JSON has
    no NaN or infinity, and the quantiles are null with the side they are on."""
    path = tmp_path / "spec.json"
    path.write_text(json.dumps(oblique(6)))
    argv = ["uncertainty", str(path), "--limits", "--obliquities", "0,80"]
    code, out, err = run_cli([*argv, "--json"])
    assert code == 0, err

    def refuse(constant: str) -> None:
        raise AssertionError(f"{constant} in the JSON")

    normal, grazing = json.loads(out, parse_constant=refuse)["limits"]
    ricochet = normal["ricochet_limit"]
    assert ricochet["ricochets_at_no_speed"] == 6 and ricochet["within_range"] == 0
    assert ricochet["v50_m_s"] is None and ricochet["v50_outside_range"] == "below"
    assert grazing["ballistic_limit"]["perforates_at_no_speed"] == 6
    assert grazing["ricochet_limit"]["ricochets_at_every_speed"] == 6
    code, out, err = run_cli(argv)
    assert code == 0, err
    assert "no ricochet limit in the range: no sample ricochets at any speed of it" in out
    assert "no ballistic limit in the range: no sample perforates at any speed of it" in out


def closed_form_shares(low_a: float, high_a: float, low_p: float, high_p: float):
    """First-order and total Sobol' indices of the closed-form ballistic limit at normal
    incidence to a ~ U(low_a, high_a) [Pa] and P* ~ U(low_p, high_p) [mm]. V = sqrt(a)
    g(P*) (tests/closed_forms.py): with A = sqrt(a) and G = g(P*) independent,
    V_a = Var A (E G)², V_p = (E A)² Var G, V_ap = Var A Var G; E A in closed form, the
    moments of G by 40-point Gauss-Legendre quadrature."""
    plate, sphere = presets.plate(PRESET), presets.DEFAULT_SPHERE

    def g(pstar_mm: float) -> float:
        constants = {**dict(plate.constants), "critical_penetration": pstar_mm * 1e-3, "a": 1.0}
        own = pi.Plate(plate.material, plate.thickness, tuple(constants.items()))
        return ballistic_limit(own, sphere, REST_SPEED_FRACTION.default)

    x, w = np.polynomial.legendre.leggauss(40)
    values = np.array([g(p) for p in low_p + (high_p - low_p) * (x + 1) / 2])
    mean_g, mean_g2 = w @ values / 2, w @ values**2 / 2
    mean_a = 2 / 3 * (high_a**1.5 - low_a**1.5) / (high_a - low_a)
    mean_a2 = (low_a + high_a) / 2
    var_a, var_g = mean_a2 - mean_a**2, mean_g2 - mean_g**2
    variance = mean_a2 * mean_g2 - (mean_a * mean_g) ** 2
    first = np.array([var_a * mean_g**2, mean_a**2 * var_g]) / variance
    return first, first + var_a * var_g / variance


def test_ballistic_limit_indices_are_the_closed_forms_variance_shares(registry):
    """At normal incidence with plugging, the sampled limits' indices to a and P* are
    the closed form's (about 3/4 and 1/4: a swapped or mislabelled pair is far outside
    the 99% intervals), and the first-order ones sum to at most 1."""
    a = presets.plate(PRESET).a
    given = {
        "preset": PRESET,
        "failure": "plugging",
        "at": {"obliquity_deg": 0.0},
        "inputs": {
            "a_N_m2": {"uniform": {"low": 0.6 * a, "high": 1.4 * a}},
            "pstar_mm": {"uniform": {"low": 2.5, "high": 3.5}},
        },
        "seed": 4,
    }
    found = ballistic_limit_indices(
        read_spec(given, registry), registry, 256, speeds=(200.0, 600.0), confidence=0.99
    )
    first, total = closed_form_shares(0.6 * a, 1.4 * a, 2.5, 3.5)
    assert found.names == ("a_N_m2", "pstar_mm") and found.evaluations == 256 * 4
    assert np.all(np.abs(found.first - first) <= found.first_halfwidth), (found.first, first)
    assert np.all(np.abs(found.total - total) <= found.total_halfwidth), (found.total, total)
    assert found.first.sum() <= 1.0 + found.first_halfwidth.sum()
    assert found.dominant() == "a_N_m2"


def test_ballistic_limit_indices_on_the_model_are_variance_shares(registry):
    """At 30 deg, with the obliquity uncertain too (each point's limit at its own
    obliquity): first-order indices sum to at most 1, and none exceeds its total."""
    given = oblique(10)
    del given["at"]["obliquity_deg"]
    given["inputs"]["obliquity_deg"] = {"uniform": {"low": 28.0, "high": 32.0}}
    found = ballistic_limit_indices(read_spec(given, registry), registry, 32)
    assert found.first.sum() <= 1.0 + found.first_halfwidth.sum()
    assert np.all(found.first - found.first_halfwidth <= found.total + found.total_halfwidth)


def test_ballistic_limit_indices_refuse_what_has_no_limit(registry):
    """An uncertain speed is named (the limit is a speed); points whose limit is beyond
    the range are counted, never taken as a number."""
    given = oblique(10)
    given["at"]["speed_m_s"] = 400.0
    given["inputs"]["speed_m_s"] = {"normal": {"mean": 400.0, "sd": 10.0}}
    with pytest.raises(UncertaintySpecError, match="inputs.speed_m_s: the ballistic limit"):
        ballistic_limit_indices(read_spec(given, registry), registry, 16)
    with pytest.raises(UncertaintySpecError, match="64 of 64 Saltelli points have no ballistic"):
        ballistic_limit_indices(read_spec(oblique(10, obliquity=80.0), registry), registry, 16)


def test_a_two_process_pool_gives_the_same_limits_and_indices(registry):
    spec = read_spec(oblique(12), registry)
    alone = sampled_limits(spec, registry, 30.0)
    with ProcessPoolExecutor(2) as pool:
        pooled = sampled_limits(spec, registry, 30.0, executor=pool)
        indices = ballistic_limit_indices(spec, registry, 16, executor=pool)
        perforation = perforation_indices(
            read_spec({**oblique(12), "at": {"obliquity_deg": 30.0, "speed_m_s": 420.0}}, registry),
            registry, 16, executor=pool,
        )  # fmt: skip
    assert np.array_equal(alone.ballistic, pooled.ballistic)
    assert np.array_equal(alone.ricochet, pooled.ricochet)
    assert np.array_equal(indices.first, ballistic_limit_indices(spec, registry, 16).first)
    spec_at = read_spec(
        {**oblique(12), "at": {"obliquity_deg": 30.0, "speed_m_s": 420.0}}, registry
    )
    assert np.array_equal(perforation.total, perforation_indices(spec_at, registry, 16).total)


def bit_for_bit(a: object, b: object) -> bool:
    """Whether ``a`` and ``b`` hold the same: attrs classes field by field, containers
    item by item, arrays by dtype, shape and bytes."""
    if attrs.has(type(a)):
        fields = attrs.fields(type(a))
        return type(a) is type(b) and all(
            bit_for_bit(getattr(a, f.name), getattr(b, f.name)) for f in fields
        )
    if isinstance(a, dict):
        return (
            isinstance(b, dict) and a.keys() == b.keys() and all(bit_for_bit(a[k], b[k]) for k in a)
        )
    if isinstance(a, list | tuple):
        return isinstance(b, list | tuple) and len(a) == len(b) and all(map(bit_for_bit, a, b))
    if isinstance(a, np.ndarray):
        return isinstance(b, np.ndarray) and (a.dtype, a.shape, a.tobytes()) == (
            b.dtype, b.shape, b.tobytes(),
        )  # fmt: skip
    return bool(a == b)


def test_each_kind_of_record_reads_back_as_computed(registry, at_30, tmp_path):
    """Sampled limits, indices and a map stored in an archive read back bit for bit."""
    spec = at_30.spec
    simulation = pi.Simulation.from_names(failure="plugging", registry=registry)
    archive = pi.Archive(tmp_path / "u.h5")
    archive.append_record("l", limits_to_record([at_30], simulation, {}))
    (back,) = read_stored(archive, "l", spec, registry)
    for name in ("ballistic", "ricochet", "speeds", "tolerance", "resolution", "scenes"):
        assert np.array_equal(getattr(back, name), getattr(at_30, name)), name
    assert back.obliquity == at_30.obliquity and back.inputs.keys() == at_30.inputs.keys()
    indices = {"perforation": perforation_indices(
        read_spec({**oblique(12), "at": {"obliquity_deg": 30.0, "speed_m_s": 420.0}}, registry),
        registry, 16)}  # fmt: skip
    archive.append_record("i", indices_to_record(indices, spec, simulation, {}))
    read = read_stored(archive, "i", spec, registry)
    assert isinstance(read, dict)
    for name in ("names", "first", "first_halfwidth", "total", "total_halfwidth", "evaluations"):
        assert np.array_equal(
            getattr(read["perforation"], name), getattr(indices["perforation"], name)
        )
    grid = outcome_grid(spec, registry, np.array([300.0, 500.0]), np.array([0.0, 45.0]))
    archive.append_record("m", map_to_record(grid, simulation, {}))
    mapped = read_stored(archive, "m", spec, registry)
    assert not isinstance(mapped, dict | tuple)
    assert np.array_equal(mapped.obliquities_deg, [0.0, 45.0])
    for name, count in grid.counts.items():
        assert np.array_equal(mapped.counts[name], count)
    other = read_spec(oblique(60, seed=7), registry)
    with pytest.raises(pi.ArchiveError, match="made for another spec"):
        read_stored(archive, "l", other, registry)
    # the same records as plateimpact wrote them before records were netCDF: read back
    # the same, and exported as the same netCDF files
    before = {name: read_stored(archive, name, spec, registry) for name in ("l", "i", "m")}
    netcdf = {name: exported(archive.path, name, tmp_path / f"{name}.nc") for name in before}
    for name, found in before.items():
        to_old_layout(record_file(archive.path, name))
        assert bit_for_bit(read_stored(archive, name, spec, registry), found), name
        old = exported(archive.path, name, tmp_path / f"{name}.old.nc")
        xarray.testing.assert_identical(old, netcdf[name])


def test_a_result_made_by_other_code_is_neither_kept_nor_replaced(registry, at_30, tmp_path):
    """resume reads back only what the code that would run now made; a record of other
    code is refused in one line, and the archive keeps it."""
    simulation = pi.Simulation.from_names(failure="plugging", registry=registry)
    settings = {"obliquities_deg": [30.0], **SEARCH}
    record = limits_to_record([at_30], simulation, settings)
    plugins = json.loads(str(record.attributes["plugins"]))
    plugins["failure"]["source_sha256"] = "0" * 64  # as if the plug-in had changed
    record.attributes["plugins"] = json.dumps(plugins)
    archive = pi.Archive(tmp_path / "u.h5")
    name = record_name(at_30.spec, KIND_LIMITS, settings)
    archive.append_record(name, record)
    index = archive.path.read_bytes()
    with pytest.raises(pi.ArchiveError, match="made by other code.*another archive"):
        kept_limits(at_30.spec, registry, [30.0], archive, resume=True)
    assert archive.path.read_bytes() == index


class Counted:
    """Simulation.run_batch, counting its calls."""

    def __init__(self, monkeypatch: pytest.MonkeyPatch) -> None:
        self.calls = 0
        run_batch = pi.Simulation.run_batch

        def counted(simulation, *args, **kwargs):
            self.calls += 1
            return run_batch(simulation, *args, **kwargs)

        monkeypatch.setattr(pi.Simulation, "run_batch", counted)


@pytest.mark.parametrize(
    "flags",
    [
        ["--limits"],
        ["--sobol", "16", "--sobol-of", "both"],
        ["--speeds", "300,600", "--obliquities", "0,45"],
    ],
)
def test_a_kept_result_is_read_back_on_resume_and_not_computed(tmp_path, monkeypatch, flags):
    path, archive = tmp_path / "spec.json", tmp_path / "u.h5"
    given = oblique(8)
    given["at"]["speed_m_s"] = 420.0  # for P(perforation); the limits take none
    if "--limits" in flags:
        del given["at"]["speed_m_s"]
    path.write_text(json.dumps(given))
    argv = ["uncertainty", str(path), *flags, "--archive", str(archive), "--json"]
    counted = Counted(monkeypatch)
    code, first, err = run_cli(argv)
    assert code == 0 and counted.calls > 0, err
    index = archive.read_bytes()
    code, _, err = run_cli(argv)  # again without --resume: refused, the archive as it was
    assert_one_line(code, err, "already has this result", "--resume")
    assert archive.read_bytes() == index
    counted.calls = 0
    code, again, err = run_cli([*argv, "--resume"])
    assert code == 0 and counted.calls == 0, err
    assert json.loads(again) == json.loads(first)
    code, shown, err = run_cli(["show", str(archive)])
    assert code == 0 and "of an uncertainty study" in shown, err


def test_a_failed_append_leaves_the_archive_as_it_was(tmp_path, monkeypatch):
    """The record is appended atomically: a fault before the index is replaced leaves
    the archive's index and its earlier study as they were."""
    path, archive = tmp_path / "spec.json", tmp_path / "u.h5"
    given = oblique(8)
    given["at"]["speed_m_s"] = 420.0
    path.write_text(json.dumps(given))
    assert run_cli(["uncertainty", str(path), "--archive", str(archive)])[0] == 0
    index, files = archive.read_bytes(), sorted(p.name for p in archive.parent.glob("u.h5.d/*"))

    def fail(stage: str) -> None:
        if stage == "flush":
            raise OSError(28, "No space left on device")

    monkeypatch.setattr(appending, "fault_point", fail)
    code, _, err = run_cli(
        ["uncertainty", str(path), "--speeds", "300,600", "--archive", str(archive)]
    )
    assert_one_line(code, err, "No space left", "unchanged")
    assert archive.read_bytes() == index
    assert sorted(p.name for p in archive.parent.glob("u.h5.d/*")) == files


def test_the_velocity_response_figure_puts_the_shots_beside_the_model(tmp_path):
    """--png with --shots: one panel per obliquity, the model's curves, the shots and
    their probit fit in one key; shots at an obliquity without limits are refused."""
    spec = {"preset": "SAE1010/1.47", "failure": "plugging", "at": {"obliquity_deg": 45},
            "inputs": {"pstar_mm": {"uniform": {"low": 4.2, "high": 5.0}}},
            "samples": 12, "seed": 1}  # fmt: skip
    path, png = tmp_path / "spec.json", tmp_path / "curve.png"
    path.write_text(json.dumps(spec))
    argv = ["uncertainty", str(path), "--limits", "--shots", SHOTS, "--png", str(png)]
    code, out, err = run_cli([*argv, "--obliquities", "0,45", "--dpi", "50"])
    assert code == 0, err
    assert png.read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"
    assert out.count("probit fit V50") == 2 and "figure:" in out
    code, _, err = run_cli(argv)  # the spec's 45 deg only: the file's shots at 0 deg
    assert_one_line(code, err, "--shots", "at 0 deg, where no limits are found")


def test_the_probability_maps_are_drawn_from_the_grid(tmp_path):
    path, png = tmp_path / "spec.json", tmp_path / "maps.png"
    path.write_text(json.dumps(oblique(6)))
    argv = ["uncertainty", str(path), "--speeds", "300:700:3", "--png", str(png)]
    assert_one_line(*run_cli(argv)[::2], "--png draws probability maps", "two or more")
    code, _, err = run_cli([*argv, "--obliquities", "0,45,70", "--dpi", "50"])
    assert code == 0 and png.read_bytes()[:8] == b"\x89PNG\r\n\x1a\n", err


@pytest.mark.parametrize(
    "flags", [["--limits"], ["--sobol", "16", "--sobol-of", "ballistic_limit"]]
)
def test_the_limits_search_and_the_indices_count_their_scenes_on_a_terminal_only(
    tmp_path, monkeypatch, flags
):
    path = tmp_path / "spec.json"
    path.write_text(json.dumps(oblique(6)))
    monkeypatch.setattr("tqdm.std.time", ticking(1.0))
    for stream, shown in ((Terminal(), True), (Pipe(), False)):
        monkeypatch.setattr(sys, "stderr", stream)
        with contextlib.redirect_stdout(io.StringIO()) as out:
            assert main(["uncertainty", str(path), *flags, "--json"]) == 0
        json.loads(out.getvalue())  # standard output: the JSON alone
        assert ("uncertainty --" in stream.getvalue()) is shown
        if shown:
            counted = stream.getvalue().rsplit(": ", 1)[-1].split("scene")[0].replace(",", "")
            assert int(counted) > 6 * 50  # a scan of ~100 speeds per sample, at the least
