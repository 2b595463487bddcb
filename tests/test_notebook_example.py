"""The gallery example docs/examples/notebook_objects.py, run as a notebook runs it: cell
by cell (``# %%``), the value of each cell's last expression displayed as its HTML
(``_repr_html_``). What it displays says, in user units, what the script was given and
what an independent source knows: the inputs, the closed-form ballistic limit at normal
incidence, the archive's way of labelling results."""

from __future__ import annotations

import ast
import math
import re
from pathlib import Path

import numpy as np
import pytest
from closed_forms import ballistic_limit

import plateimpact as pi

EXAMPLE = Path(__file__).resolve().parents[1] / "docs" / "examples" / "notebook_objects.py"
#: What the script gives (its inputs): the grid's speeds [m/s] and obliquities [deg].
SPEEDS = [200.0, 300.0, 450.0, 700.0]
OBLIQUITIES_DEG = [0.0, 45.0, 60.0]


def run_as_notebook(path: Path) -> tuple[dict[str, object], list[object]]:
    """Execute ``path`` cell by cell in one namespace; returns the namespace and the value
    of every cell that ends in an expression (a notebook displays it), as a notebook or
    sphinx-gallery would: the module docstring and None are not displayed."""
    namespace: dict[str, object] = {"__name__": "__main__", "__file__": str(path)}
    shown: list[object] = []
    for source in re.split(r"^# %%.*$", path.read_text(), flags=re.M):
        tree = ast.parse(source)
        if not tree.body:
            continue
        last = tree.body[-1] if isinstance(tree.body[-1], ast.Expr) else None
        body = tree.body[:-1] if last is not None else tree.body
        exec(compile(ast.Module(body, type_ignores=[]), str(path), "exec"), namespace)
        if last is None or isinstance(last.value, ast.Constant):  # the docstring
            continue
        value = eval(compile(ast.Expression(last.value), str(path), "eval"), namespace)
        if value is not None:
            shown.append(value)
    return namespace, shown


@pytest.fixture(scope="module")
def notebook() -> tuple[dict[str, object], list[object]]:
    return run_as_notebook(EXAMPLE)


def html_of(shown: list[object], kind: type) -> str:
    (found,) = [value for value in shown if type(value) is kind]
    html = found._repr_html_()
    assert isinstance(html, str) and html.startswith("<")
    return html


def test_the_example_is_a_gallery_script_with_a_title_and_cells():
    text = EXAMPLE.read_text()
    docstring = ast.get_docstring(ast.parse(text))
    assert docstring is not None
    title, underline = docstring.splitlines()[:2]
    assert title and underline == "=" * len(title)
    assert text.count("\n# %%") >= 8


def test_every_displayed_value_has_html_and_a_short_text(notebook):
    _, shown = notebook
    kinds = {type(value).__name__ for value in shown}
    assert {"SceneBatch", "BatchResult", "Result", "Trajectory", "Limits", "V50Fit"} <= kinds
    assert {"Dataset", "DataFrame"} <= kinds
    for value in shown:
        assert isinstance(value._repr_html_(), str)
        if type(value).__module__.startswith("plateimpact"):
            text = repr(value)
            assert "\n" not in text and " object at 0x" not in text and "array(" not in text
            assert len(text) < 400


def test_the_batch_shows_the_inputs_it_was_given_in_user_units(notebook):
    namespace, shown = notebook
    html = html_of(shown, pi.SceneBatch)
    assert "<th>impact obliquity [deg]</th><td>0, 45, 60</td>" in html
    assert "<th>impact speed [m/s]</th><td>200, 300, 450, 700</td>" in html
    assert "<th>thickness [mm]</th><td>1.47</td>" in html  # the preset's name says 1.47 mm
    assert "impact obliquity 0, 45, 60 deg" in repr(namespace["batch"])


def test_the_results_count_every_scene_and_show_them_in_degrees(notebook):
    namespace, shown = notebook
    results = namespace["results"]
    html = html_of(shown, pi.BatchResult)
    counts = re.search(r"<caption>outcomes</caption>\n.*\n<tr>(.*)</tr>", html).group(1)
    numbers = [int(n) for n in re.findall(r"<td>([\d,]+)</td>", counts)]
    assert sum(numbers[:3]) == len(SPEEDS) * len(OBLIQUITIES_DEG)
    assert numbers[:3] == [int(np.sum(results.outcome == o)) for o in pi.Outcome]
    # the first rows of the scenes' table: the grid is obliquity-major
    scenes = html.split("<caption>scenes</caption>")[1]
    rows = re.findall(r"<tr><td>(\d+)</td><td>([^<]*)</td><td>([^<]*)</td>", scenes)
    assert [(float(s), float(o)) for _, s, o in rows[:4]] == [(s, 0.0) for s in SPEEDS]


def test_a_result_and_its_path_say_degrees_not_radians(notebook):
    namespace, _ = notebook
    result, trajectory = namespace["result"], namespace["result"].trajectory
    text = repr(result)
    degrees = f"{math.degrees(result.exit_obliquity):.6g}"
    assert f"exit obliquity {degrees} deg" in text
    assert f"{result.exit_obliquity:.4g}" not in text and "rad" not in text
    assert f"<th>exit obliquity [deg]</th><td>{degrees}</td>" in result._repr_html_()
    # the path: its sample count, and it starts at the scene's 60 deg and 450 m/s
    path = repr(trajectory)
    assert path.startswith(f"Trajectory({trajectory.time.size} samples over 0 to ")
    assert f"{result.contact_time * 1e6:.6g} us" in path
    assert "speed 450 to" in path and "obliquity 60 to" in path
    assert result.outcome.label in path


def test_the_tables_round_trip_the_inputs_with_units(notebook):
    namespace, _ = notebook
    results, dataset, frame = namespace["results"], namespace["dataset"], namespace["frame"]
    np.testing.assert_array_equal(dataset["impact_speed"].values, np.tile(SPEEDS, 3))
    np.testing.assert_allclose(
        dataset["impact_obliquity"].values, np.repeat(np.radians(OBLIQUITIES_DEG), 4), rtol=1e-15
    )
    assert dataset["impact_speed"].attrs["units"] == "m/s"
    assert dataset["impact_obliquity"].attrs["units"] == "rad"
    assert dataset["exit_speed"].attrs["units"] == "m/s"
    np.testing.assert_array_equal(dataset["exit_speed"].values, results.exit_speed)
    np.testing.assert_allclose(
        frame["impact_obliquity_deg"], np.repeat(OBLIQUITIES_DEG, 4), rtol=1e-13, atol=1e-13
    )
    np.testing.assert_allclose(
        frame["exit_obliquity_deg"], np.degrees(results.exit_obliquity), rtol=1e-13
    )
    assert list(frame["outcome"]) == [pi.Outcome(int(c)).label for c in results.outcome]
    assert frame.attrs["units"]["exit_obliquity_deg"] == "deg"


def test_the_limits_shown_are_the_closed_form_ballistic_limit(notebook):
    namespace, shown = notebook
    limits, simulation = namespace["limits"], namespace["simulation"]
    exact = ballistic_limit(limits.plate, limits.sphere, simulation.model.rest_speed_fraction)
    frame = limits.to_dataframe()
    assert frame.loc[0.0, "ballistic_limit_m_s"] == pytest.approx(
        exact, abs=limits.tolerance / 2 + 1e-6
    )
    html = html_of(shown, pi.limits.Limits)
    assert f"<td>0</td><td>{limits.lines[0].ballistic_limit:.2f}</td>" in html
    assert "<th>ballistic limit [m/s]</th>" in html and "<th>impact obliquity [deg]</th>" in html


def test_the_v50_from_shots_is_the_v50_from_arrays(notebook):
    namespace, shown = notebook
    fit, same = namespace["fit"], namespace["same"]
    assert fit.to_json() == same.to_json()
    assert fit.rounds == 24  # the file's 24 shots at 0 deg
    html = html_of(shown, pi.V50Fit)
    assert f"<tr><td>V50</td><td>{fit.v50_m_s:.5g}</td>" in html
    assert "<th>estimate [m/s]</th>" in html
