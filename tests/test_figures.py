"""Study figures for print: the grid of panels, the outcome key, curves that never cross an
outcome change, embedment in the strips, and --dpi, SVG and PDF from the command line."""

from __future__ import annotations

import contextlib
import io
import math
import struct
from pathlib import Path

import numpy as np
import pytest
from matplotlib.colors import to_rgba

import plateimpact as pi
from plateimpact.cli import main as cli
from plateimpact.figures import exit_curves, style
from plateimpact.limits import Regime, regime_codes

SPEEDS = np.arange(50.0, 1501.0, 50.0)  # 30 speeds: every outcome of the 3.18-mm plate
EIGHT = [0, 10, 20, 30, 40, 50, 60, 70]


@pytest.fixture(scope="module")
def eight_obliquities():
    """The 3.18-mm plate at eight obliquities, with its P* and a plate that never fails."""
    study = pi.Study.grid(
        "eight",
        ["2024-T3/3.18"],
        EIGHT,
        SPEEDS,
        [pi.Variant("plugging"), pi.Variant("intact", failure="intact")],
    )
    return study.run()


@pytest.fixture(scope="module")
def eight_panels(eight_obliquities):
    """The figure of ``eight_obliquities``, drawn once: the tests only read it."""
    return exit_curves.plot_study(eight_obliquities)


def panels_of(fig):
    """{title: (speed axes, obliquity axes, strip axes)}: each panel's axes, top to bottom."""
    axes = fig.axes
    return {axes[k].get_title(): tuple(axes[k : k + 3]) for k in range(0, len(axes), 3)}


def panel_scenes(results, obliquity):
    index = np.flatnonzero(np.isclose(np.degrees(results.study.scenes.impact_obliquity), obliquity))
    return index[np.argsort(results.study.scenes.impact_speed[index])]


def curve_lines(ax):
    return [line for line in ax.get_lines() if len(line.get_xdata())]


def run_of(line, runs):
    """The run a line belongs to, by its style (RUN_STYLES: one colour per run)."""
    colours = [to_rgba(style.RUN_STYLES[k]["color"]) for k in range(len(runs))]
    return runs[colours.index(to_rgba(line.get_color()))]


@pytest.mark.parametrize("count", [1, 3, 4, 5, 8])
def test_the_panels_form_a_grid_of_at_most_four_columns(count):
    study = pi.Study.grid("g", ["2024-T3/3.18"], EIGHT[:count], SPEEDS[::6], pi.Variant("v"))
    fig = exit_curves.plot_study(study.run())
    speed_axes = fig.axes[::3]
    assert len(speed_axes) == count
    rows = {ax.get_subplotspec().rowspan.start // 3 for ax in speed_axes}
    columns = {ax.get_subplotspec().colspan.start for ax in speed_axes}
    assert len(rows) == math.ceil(count / 4) and len(columns) <= 4
    # Journal widths: two columns (7.2 in), or one (3.5 in) for a single panel.
    assert fig.get_size_inches()[0] == pytest.approx(3.5 if count == 1 else 7.2)


def test_the_key_names_every_run_and_every_outcome_present(eight_obliquities, eight_panels):
    fig = eight_panels
    (legend,) = fig.legends
    labels = [text.get_text() for text in legend.get_texts()]
    assert labels[:2] == ["plugging", "intact"]
    for run in ("plugging", "intact"):
        for outcome in np.unique(eight_obliquities[run].outcome):
            assert any(label.startswith(pi.Outcome(outcome).label) for label in labels[2:])
    present = {
        Regime.of_code(c).label for run in ("plugging", "intact")
        for c in regime_codes(eight_obliquities[run])
    }  # fmt: skip
    assert set(labels[2:]) == present


def key_colours(legend):
    """{label: face colour} of a legend's coloured patches."""
    return {
        text.get_text(): tuple(handle.get_facecolor())
        for text, handle in zip(legend.get_texts(), legend.legend_handles, strict=True)
        if hasattr(handle, "get_facecolor")
    }


def test_the_family_key_and_the_outcome_maps_share_one_palette(eight_panels):
    from plateimpact.figures.limits_and_maps import plot_bands  # noqa: PLC0415

    family = key_colours(eight_panels.legends[0])
    found = pi.limits.along_speed(
        pi.Simulation.from_names(), pi.presets.DEFAULT_SPHERE,
        pi.presets.plate("2024-T3/3.18"), np.radians([0.0, 60.0]), resolution=40.0,
    )  # fmt: skip
    bands = key_colours(plot_bands(found, "x").legends[0])
    common = set(family) & set(bands)
    assert {"ricochet", "embedment", "perforation"} <= common
    assert all(family[label] == bands[label] for label in common)


def test_the_bands_key_names_each_limit_mark_and_sits_clear_of_the_axis_label():
    from plateimpact.figures.limits_and_maps import plot_bands  # noqa: PLC0415

    found = pi.limits.along_speed(
        pi.Simulation.from_names(), pi.presets.DEFAULT_SPHERE,
        pi.presets.plate("2024-T3/3.18"), np.radians([30.0, 60.0]), resolution=40.0,
    )  # fmt: skip
    assert all(line.ricochet_limit is not None for line in found.lines)
    fig = plot_bands(found, "x")
    (key,) = fig.legends
    labels = [text.get_text() for text in key.get_texts()]
    assert "ballistic limit" in labels and "ricochet limit" in labels
    marks = {line.get_linestyle() for line in fig.axes[0].get_lines()}
    assert len(marks) == 2  # the two limits drawn differently, both keyed
    assert all(colour != "w" for line in fig.axes[0].get_lines()
               for colour in [line.get_color()])  # fmt: skip
    from matplotlib.backends.backend_agg import FigureCanvasAgg  # noqa: PLC0415

    canvas = FigureCanvasAgg(fig)
    canvas.draw()
    renderer = canvas.get_renderer()
    label_box = fig.axes[0].xaxis.label.get_window_extent(renderer)
    key_box = key.get_window_extent(renderer)
    assert key_box.y1 <= label_box.y0  # below the x label, not over it


def test_no_line_joins_two_outcomes_and_embedments_are_not_lines(eight_obliquities, eight_panels):
    results = eight_obliquities
    runs = list(results.runs)
    fig = eight_panels
    drawn = 0
    for ob in EIGHT:
        speed_ax, obliquity_ax, _ = panels_of(fig)[f"2024-T3/3.18, {ob}°"]
        index = panel_scenes(results, ob)
        speeds = results.study.scenes.impact_speed[index]
        for ax in (speed_ax, obliquity_ax):
            for line in curve_lines(ax):
                run = run_of(line, runs)
                at = np.searchsorted(speeds, line.get_xdata())
                np.testing.assert_array_equal(speeds[at], line.get_xdata())  # scenes drawn
                outcomes = results[run].outcome[index[at]]
                assert np.all(outcomes == outcomes[0]), (ob, run, outcomes)
                assert outcomes[0] != pi.Outcome.EMBEDMENT
                drawn += 1
    assert drawn > 40


def test_exit_curves_break_at_every_regime_change():
    speeds = np.arange(100.0, 900.0, 20.0)
    batch = pi.SceneBatch.grid(
        pi.presets.DEFAULT_SPHERE, pi.presets.plate("2024-T3/6.35"), speeds, np.radians([45.0])
    )
    result = pi.Simulation.from_names().run_batch(batch)
    fig, axes = style.figure(2, 1)
    exit_curves.plot_exit_curves(axes, speeds, result, label="run")
    codes = regime_codes(result)
    drawn = [np.searchsorted(speeds, line.get_xdata()) for line in axes[0].get_lines()]
    stretches = np.split(np.arange(codes.size), np.flatnonzero(np.diff(codes)) + 1)
    embedded = codes // 2 == pi.Outcome.EMBEDMENT
    assert len(stretches) >= 3 and embedded.any()  # the case is a real one
    # One line per stretch of one regime but embedment; together every exit, once.
    assert [list(at) for at in drawn] == [list(s) for s in stretches if not embedded[s[0]]]
    assert [line.get_label() for line in axes[0].get_lines()].count("run") == 1


def test_the_strips_show_every_runs_outcome_at_every_scene(eight_obliquities, eight_panels):
    results = eight_obliquities
    fig = eight_panels
    for ob in (0, 30, 60):
        strip = panels_of(fig)[f"2024-T3/3.18, {ob}°"][2]
        index = panel_scenes(results, ob)
        speeds = results.study.scenes.impact_speed[index]
        bars = []
        for collection in strip.collections:
            (x0, y0), (x1, y1) = (
                collection.get_paths()[0].vertices.min(0),
                (collection.get_paths()[0].vertices.max(0)),
            )
            bars.append((x0, x1, 0.5 * (y0 + y1), tuple(collection.get_facecolor()[0])))
        for row, run in enumerate(results.runs):
            for speed, code in zip(speeds, regime_codes(results[run])[index], strict=True):
                colour = to_rgba(style.REGIME_COLOURS[Regime.of_code(code)])
                covering = [b for b in bars if b[0] <= speed <= b[1] and round(b[2]) == row]
                assert covering and all(b[3] == colour for b in covering), (ob, run, speed)


def test_normal_incidence_says_what_the_obliquity_is_instead_of_a_flat_line(
    eight_obliquities, eight_panels
):
    fig = eight_panels
    _, obliquity_ax, _ = panels_of(fig)["2024-T3/3.18, 0°"]
    assert not curve_lines(obliquity_ax)
    (note,) = obliquity_ax.texts
    assert "every exit obliquity is 0°" in note.get_text()
    for run in eight_obliquities.runs:  # what the note says is what the runs found
        part = eight_obliquities[run].take(panel_scenes(eight_obliquities, 0))
        exits = part.exit_obliquity[part.outcome != pi.Outcome.EMBEDMENT]
        np.testing.assert_array_equal(exits, 0.0)
    _, oblique_ax, _ = panels_of(fig)["2024-T3/3.18, 30°"]
    assert curve_lines(oblique_ax) and not oblique_ax.texts


# The command line: --dpi, and the format from the file name.


#: The example shot files (studies/data).
SHOTS = Path(__file__).resolve().parents[1] / "studies" / "data"


def run_cli(argv):
    out, err = io.StringIO(), io.StringIO()
    with contextlib.redirect_stdout(out), contextlib.redirect_stderr(err):
        try:
            code = cli(argv)
        except SystemExit as exc:  # argparse's own errors
            code = int(exc.code or 0)
    return code, err.getvalue()


@pytest.fixture(scope="module")
def archive(tmp_path_factory):
    """A study at two obliquities: its figure has two panels, the fewest drawn at the
    page width (one panel is one column wide)."""
    path = tmp_path_factory.mktemp("figures") / "a.h5"
    pi.Study.grid("t318", ["2024-T3/3.18"], [0, 45], SPEEDS[::3], pi.Variant("plugging")).run(
        archive=path
    )
    return path


def png_size(path):
    head = path.read_bytes()[:24]
    assert head[:8] == b"\x89PNG\r\n\x1a\n"
    return struct.unpack(">II", head[16:24])


def test_dpi_sets_the_pixels_of_a_journal_width_figure(archive, tmp_path):
    sizes = {}
    for dpi in (50, 100, 300):
        png = tmp_path / f"{dpi}.png"
        assert run_cli(["plot", str(archive), "--run", "plugging", "--out", str(png),
                        "--dpi", str(dpi)])[0] == 0  # fmt: skip
        sizes[dpi] = png_size(png)
    for dpi, (width, height) in sizes.items():
        assert width == round(7.2 * dpi)  # the page width of a journal, in inches
        assert height == pytest.approx(sizes[100][1] * dpi / 100, abs=1)


def test_every_figure_flag_takes_its_dpi(tmp_path):
    """A figure without a layout engine is cropped to what is drawn, so its pixels are
    not dpi x inches: twice the dpi gives about twice the pixels in each direction."""
    sizes = {}
    for dpi in (60, 120):
        png = tmp_path / f"c{dpi}.png"
        argv = ["crater", "--preset", "2024-T3/3.18", "--speed", "500", "--obliquity", "60",
                "--png", str(png), f"--dpi={dpi}"]  # fmt: skip
        assert run_cli(argv)[0] == 0
        sizes[dpi] = png_size(png)
    assert sizes[120][0] == pytest.approx(2 * sizes[60][0], rel=0.05)


def test_svg_and_pdf_are_written_by_their_extension(archive, tmp_path):
    svg, pdf = tmp_path / "x.svg", tmp_path / "x.pdf"
    for path in (svg, pdf):
        assert run_cli(["plot", str(archive), "--run", "plugging", "--out", str(path)])[0] == 0
    assert svg.read_bytes().startswith(b"<?xml") and b"<svg" in svg.read_bytes()[:2000]
    assert pdf.read_bytes().startswith(b"%PDF-") and pdf.read_bytes().rstrip().endswith(b"%%EOF")


@pytest.mark.parametrize("dpi", ["0", "-100", "49", "1201", "nan", "inf", "many"])
def test_a_bad_dpi_is_one_line_naming_the_flag_and_the_range(archive, tmp_path, dpi):
    png = tmp_path / "x.png"
    for argv in (
        ["plot", str(archive), "--run", "plugging", "--out", str(png), f"--dpi={dpi}"],
        ["reproduce", "--out", str(tmp_path / "report"), f"--dpi={dpi}"],
        ["crater", "--preset", "2024-T3/3.18", "--speed", "500", "--obliquity", "60",
         "--png", str(png), f"--dpi={dpi}"],
        ["limits", "--preset", "2024-T3/3.18", "--obliquities", "45", "--png", str(png),
         f"--dpi={dpi}"],
        ["map", "--preset", "2024-T3/3.18", "--png", str(png), f"--dpi={dpi}"],
        ["compare", str(archive), "plugging", "plugging", "--png", str(png), f"--dpi={dpi}"],
        ["validate", str(SHOTS / "oblique_SAE1010_1.47mm_pstar4.6.csv"), "--preset",
         "SAE1010/1.47", "--png", str(png), f"--dpi={dpi}"],
        ["v50", str(SHOTS / "gonogo_SAE1010_1.47mm.csv"), "--by-obliquity", "--png", str(png),
         f"--dpi={dpi}"],
    ):  # fmt: skip
        code, err = run_cli(argv)
        assert code == 2 and err.count("\n") == 1, err
        assert "--dpi" in err and "from 50 to 1200" in err and "Traceback" not in err
    assert not png.exists() and not (tmp_path / "report").exists()


def test_panels_with_no_exit_or_one_speed_are_drawn_and_say_so():
    embedded = pi.Study.grid("e", ["6061-T6/9.53"], [0], [100.0, 200.0, 300.0], pi.Variant("v"))
    results = embedded.run()
    assert np.all(results["v"].outcome == pi.Outcome.EMBEDMENT)
    speed_ax, obliquity_ax, strip = exit_curves.plot_study(results).axes
    assert not curve_lines(speed_ax) and not curve_lines(obliquity_ax)
    assert "no sphere leaves the plate" in obliquity_ax.texts[0].get_text()
    assert len(strip.collections) == 1  # one embedment bar over the three speeds
    one = pi.Study.grid("o", ["2024-T3/3.18"], [45], [900.0], pi.Variant("v")).run()
    speed_ax, _, strip = exit_curves.plot_study(one).axes
    (dot,) = curve_lines(speed_ax)
    assert dot.get_marker() == "." and list(dot.get_xdata()) == [900.0]


def test_a_crater_figure_keys_its_floor_the_centres_path_and_the_spheres():
    from plateimpact.figures.crater_sections import plot_crater  # noqa: PLC0415
    from plateimpact.model.crater import crater_section  # noqa: PLC0415

    sphere, plate = pi.presets.DEFAULT_SPHERE, pi.presets.plate("2024-T3/3.18")
    result = pi.Simulation.from_names().run(
        pi.Scene(sphere, plate, 500.0, math.radians(45.0)), record_trajectory=True
    )
    section = crater_section(result.trajectory, sphere.radius, thickness=plate.thickness)
    fig, ax = style.figure()
    plot_crater(ax, section, trajectory=result.trajectory, radius=sphere.radius)
    labels = [text.get_text() for text in ax.legend().get_texts()]
    assert labels == ["crater floor", "front surface", "path of the centre",
                      "sphere at first contact, deepest, last"]  # fmt: skip
    circles = [line for line in ax.get_lines() if line.get_label() == "_nolegend_"]
    assert len(circles) == 2  # the three spheres keyed once


def test_the_study_paths_have_no_colour_too_pale_for_white_paper(tmp_path):
    from plateimpact.figures.study_paths import plot_study_paths  # noqa: PLC0415

    study = pi.Study.grid("p", ["2024-T3/3.18"], [60.0], np.linspace(150.0, 1000.0, 6),
                          pi.Variant("v"))  # fmt: skip
    fig = plot_study_paths(study.run(record_trajectory=True), kind="trajectory")
    (ax,) = fig.axes
    for line in ax.get_lines():  # WCAG 2's contrast of graphics with white: at least 3:1
        linear = [c / 12.92 if c <= 0.04045 else ((c + 0.055) / 1.055) ** 2.4
                  for c in to_rgba(line.get_color())[:3]]  # fmt: skip
        luminance = 0.2126 * linear[0] + 0.7152 * linear[1] + 0.0722 * linear[2]
        assert 1.05 / (luminance + 0.05) >= 3.0, line.get_label()
    labels = [text.get_text() for text in ax.get_legend().get_texts()]
    assert labels[-2:] == ["front surface", "back surface"]
