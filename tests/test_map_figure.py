"""The outcome-map figure: one image per plate in the regime palette, cells where the grid
puts them, the located boundaries, a key of the regimes present, axis labels in m/s and
deg, panels in a grid at journal width with no label overlapping another; and
``plateimpact map --png`` still writes it."""

from __future__ import annotations

import math
import struct

import attrs
import numpy as np
import pytest
from matplotlib.backends.backend_agg import FigureCanvasAgg
from matplotlib.colors import to_rgba
from matplotlib.text import Text
from test_output_files import run_cli

import plateimpact as pi
from plateimpact import limits, presets
from plateimpact.figures.limits_and_maps import draw_outcome_map, plot_outcome_map
from plateimpact.figures.style import REGIME_COLOURS, figure
from plateimpact.limits import Regime

PLATES = ["2024-T3/3.18", "2024-T3/6.35", "SAE1010/1.47"]
SPEEDS, SAMPLES = (100.0, 1500.0), 15  # every 100 m/s
ROWS_DEG = [0.0, 15.0, 30.0, 45.0, 60.0, 75.0]
MAIN = {"ricochet", "embedment", "perforation"}


@pytest.fixture(scope="module")
def maps():
    found = limits.outcome_maps(
        pi.Simulation.from_names(), presets.DEFAULT_SPHERE,
        [presets.plate(name) for name in PLATES], SPEEDS, SAMPLES, np.radians(ROWS_DEG),
    )  # fmt: skip
    return list(zip(PLATES, found, strict=True))


def rendered(fig, dpi=100):
    """The figure drawn by Agg at ``dpi``: (canvas, RGBA pixels, top row first)."""
    fig.set_dpi(dpi)
    canvas = FigureCanvasAgg(fig)
    canvas.draw()
    return canvas, np.asarray(canvas.buffer_rgba())


def key_of(fig):
    """{label: face colour} of the figure's one key."""
    (legend,) = fig.legends
    return {
        text.get_text(): tuple(handle.get_facecolor())
        for text, handle in zip(legend.get_texts(), legend.legend_handles, strict=True)
    }


def present_in(found_maps):
    return {Regime.of_code(int(c)) for _, found in found_maps for c in np.unique(found.regime)}


@pytest.mark.parametrize("count", [1, 2, 3, 4, 5])
def test_one_image_per_plate_in_a_grid_at_journal_width(maps, count):
    chosen = [(f"{label} #{k}", found) for k, (label, found) in
              enumerate((maps * 2)[:count])]  # fmt: skip
    fig = plot_outcome_map(chosen)
    assert len(fig.axes) == count  # the grid's spare cells are removed
    columns = {ax.get_subplotspec().colspan.start for ax in fig.axes}
    rows = {ax.get_subplotspec().rowspan.start for ax in fig.axes}
    assert len(columns) == min(count, 1 if count == 1 else 2 if count in (2, 4) else 3)
    assert len(rows) == math.ceil(count / len(columns))
    # Journal widths [in]: the page (two columns) for several maps, one column for one.
    assert fig.get_size_inches()[0] == pytest.approx(3.5 if count == 1 else 7.2)
    for ax, (label, found) in zip(fig.axes, chosen, strict=True):
        assert len(ax.images) == 1 and not ax.collections  # one image, no contour paths
        assert ax.get_title(loc="left") == label  # short enough not to wrap
        assert ax.get_title(loc="right") == found.limits.model["failure"] == "plugging"
        assert len(ax.get_lines()) == len(found.boundary_curves())
    assert "plugging" in fig.get_suptitle() and "0.01 m/s" in fig.get_suptitle()


def test_the_key_names_the_regimes_present_in_the_shared_palette(maps):
    fig = plot_outcome_map(maps)
    key = key_of(fig)
    present = present_in(maps)
    assert MAIN <= {r.label for r in present}
    assert list(key) == [r.label for r in pi.limits.REGIMES if r in present]  # report order
    for regime in present:
        assert key[regime.label] == to_rgba(REGIME_COLOURS[regime])


def test_the_axes_are_labelled_with_units_at_the_edges_of_the_grid(maps):
    fig = plot_outcome_map([*maps, *maps[:2]])  # five panels: 3 + 2
    bottom = {2, 3, 4}  # no panel below them
    for n, ax in enumerate(fig.axes):
        assert ax.get_xlabel() == ("impact speed [m/s]" if n in bottom else "")
        assert ax.get_ylabel() == ("impact obliquity [deg]" if n % 3 == 0 else "")
        # The speeds are numbered wherever there is no panel below, on one shared grid.
        assert any(t.get_visible() for t in ax.get_xticklabels()) == (n in bottom)
    fig, ax = figure()
    draw_outcome_map(ax, maps[0][1], "alone")
    assert (ax.get_xlabel(), ax.get_ylabel()) == ("impact speed [m/s]", "impact obliquity [deg]")
    labels = [text.get_text() for text in ax.get_legend().get_texts()]
    assert labels == [r.label for r in pi.limits.REGIMES if r in present_in(maps[:1])]


def test_every_cell_is_drawn_in_its_regimes_colour_where_the_grid_puts_it(maps):
    """A checkerboard of regimes on uneven rows, read back from the pixels: each cell
    reaches half-way to its neighbours (nearest cells), whatever the rows' spacing."""
    label, found = maps[0]
    rows = np.radians([0.0, 10.0, 45.0, 60.0, 70.0])
    codes = [r.code for r in pi.limits.REGIMES]
    pattern = np.array(codes)[(np.arange(5)[:, None] + 2 * np.arange(SAMPLES)) % len(codes)]
    board = attrs.evolve(
        found, obliquities=rows, regime=pattern,
        exit_speed=np.zeros(pattern.shape), exit_obliquity=np.zeros(pattern.shape),
        limits=attrs.evolve(found.limits, lines=()),  # no boundary drawn over the cells
    )  # fmt: skip
    fig = plot_outcome_map([(label, board)])
    _, pixels = rendered(fig)
    (ax,) = fig.axes
    speeds, degrees = board.speeds, np.degrees(rows)
    for j, obliquity in enumerate(degrees):
        below = (obliquity - degrees[j - 1]) / 2 if j else (degrees[1] - degrees[0]) / 2
        above = (degrees[j + 1] - obliquity) / 2 if j + 1 < len(degrees) else below
        for i, speed in enumerate(speeds):
            colour = np.array(to_rgba(REGIME_COLOURS[Regime.of_code(int(pattern[j, i]))]))
            for dv, dob in [(0, 0), (-40, 0), (40, 0), (0, -0.8 * below), (0, 0.8 * above)]:
                x, y = ax.transData.transform((speed + dv, obliquity + dob))
                got = pixels[pixels.shape[0] - 1 - int(y), int(x)] / 255.0
                np.testing.assert_allclose(got, colour, atol=1.5 / 255, err_msg=(j, i, dv, dob))


def bbox_of(text, renderer):
    return text.get_window_extent(renderer)


@pytest.mark.parametrize("count", [1, 4, 5])
def test_no_label_overlaps_another_and_all_are_on_the_page(maps, count):
    chosen = (maps * 2)[:count]
    long = "plates/a_plate_file_with_a_long_name_in_a_folder_with_another_long_name.json"
    chosen = [(long if k == 0 else label, found) for k, (label, found) in enumerate(chosen)]
    fig = plot_outcome_map(chosen)
    canvas, _ = rendered(fig, dpi=150)
    renderer = canvas.get_renderer()
    page = fig.bbox
    panels = [ax.get_tightbbox(renderer) for ax in fig.axes]  # frame, ticks, labels, titles
    others = [fig.legends[0].get_window_extent(renderer), bbox_of(fig._suptitle, renderer)]
    boxes = panels + others
    for a in range(len(boxes)):
        assert page.x0 <= boxes[a].x0 and boxes[a].x1 <= page.x1 + 0.5
        assert page.y0 <= boxes[a].y0 and boxes[a].y1 <= page.y1 + 0.5
        for b in range(a):
            assert not boxes[a].overlaps(boxes[b]), (a, b)
    for ax, (label, _) in zip(fig.axes, chosen, strict=True):
        left, right = (bbox_of(t, renderer) for t in ax.findobj(Text) if t.get_text() and (
            "".join(t.get_text().split()) in (label, "plugging")
        ))  # fmt: skip
        assert not left.overlaps(right)


def png_size(path):
    head = path.read_bytes()[:24]
    assert head[:8] == b"\x89PNG\r\n\x1a\n"
    return struct.unpack(">II", head[16:24])


def test_map_png_is_written_at_journal_width(tmp_path):
    small = ["--speeds", "100:900:20", "--obliquities", "0:60:4"]
    one, two = tmp_path / "one.png", tmp_path / "two.png"
    code, _, err = run_cli(["map", "--preset", "2024-T3/3.18", *small, "--png", str(one)])
    assert code == 0, err
    argv = ["map", "--preset", "2024-T3/3.18", "--preset", "2024-T3/6.35", *small,
            "--png", str(two), "--dpi", "100"]  # fmt: skip
    code, _, err = run_cli(argv)
    assert code == 0, err
    assert png_size(one)[0] == round(3.5 * 150)  # one column at the default 150 dpi
    assert png_size(two)[0] == round(7.2 * 100)  # the page at --dpi 100
