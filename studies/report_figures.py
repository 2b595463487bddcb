"""Figures that compare plateimpact with the report's comparison runs.

    python studies/report_figures.py [--out docs/figures]

* fig30_31_2024T3_3.18mm_60deg.png: exit speed and exit obliquity against impact speed
  for the 3.18-mm plate at 60°, with its P* (solid) and with an extremely large P*
  (dashed), each run's outcome ranges in a strip below, as in the report's Figures 30–31.
* fig35_craters_6061T6_9.53mm_60deg.png: predicted crater sections for the 9.53-mm
  plate at 60° and 0.263 and 0.737 km/s (the speeds of Figure 35).
* hinge_geometry.png: the hinge (finger) failure model at three moments of one impact.
* outcome_map_2024T3_3.18mm.png: the outcome map of the 3.18-mm plate (200 x 86 grid,
  boundaries to 0.01 m/s), and limit_curves.png: ballistic and ricochet limits of the
  five plates against obliquity (docs/limits.md).
"""

from __future__ import annotations

import argparse
import math
from pathlib import Path

import numpy as np
from matplotlib.figure import Figure

import plateimpact as pi
from plateimpact import limits, presets
from plateimpact.figures import crater_sections, exit_curves, saving, style
from plateimpact.model.crater import crater_section
from plateimpact.units import deg, mm
from plateimpact_plugins import Hinge

SPHERE = presets.DEFAULT_SPHERE


def figure_30_31(out: Path) -> Path:
    """The 3.18-mm plate at 60°: its P* (plugging) against a plate that never fails."""
    pstar = presets.plate("2024-T3/3.18").critical_penetration
    study = pi.Study.grid(
        "fig30_31",
        ["2024-T3/3.18"],
        [60],
        np.linspace(50.0, 1500.0, 146),
        [pi.Variant("plugging"), pi.Variant("large-pstar", failure="intact")],
        description=f"Figures 30-31, P* = {pstar / mm:g} mm against a plate that never fails",
    )
    path = out / "fig30_31_2024T3_3.18mm_60deg.png"
    saving.save(exit_curves.plot_study(study.run()), str(path))
    return path


def figure_35(out: Path) -> Path:
    path = out / "fig35_craters_6061T6_9.53mm_60deg.png"
    saving.save(craters_figure_35(), str(path))
    return path


def craters_figure_35() -> Figure:
    """Crater sections of the 9.53-mm plate at 60° and Figure 35's speeds (eqs 31–39)."""
    plate = presets.plate("6061-T6/9.53")
    simulation = pi.Simulation.from_names()
    fig, axes = style.figure(2, 1, figsize=(8, 7), layout="constrained")
    for ax, speed in zip(axes, (263.0, 737.0), strict=True):
        result = simulation.run(pi.Scene(SPHERE, plate, speed, 60 * deg), record_trajectory=True)
        section = crater_section(result.trajectory, SPHERE.radius, thickness=plate.thickness)
        crater_sections.plot_crater(ax, section, trajectory=result.trajectory, radius=SPHERE.radius)
        ax.set_title(
            f"6061-T6, 9.53 mm, 60°, {speed / 1e3:.3f} km/s: {result.outcome.label}, "
            f"crater {section.length / mm:.1f} × {section.max_depth / mm:.2f} mm"
        )
    return fig


def hinge_geometry(out: Path) -> Path:
    """Three moments of a hinge failure: onset (β held at 2α*), release (θ = θ1), end."""
    plate = presets.plate("SAE1010/1.47")
    hinge = Hinge()
    simulation = pi.Simulation(
        pi.ImpactModel(pi.default_registry().create("resistance", "poncelet"), hinge),
        pi.default_registry().create("integrator", "segment"),
    )
    scene = pi.Scene(SPHERE, plate, 500.0, 30 * deg)
    result = simulation.run(scene, record_trajectory=True)
    t = result.trajectory
    beta = t.failure_state["finger_angle"]
    failed = np.flatnonzero(np.isfinite(beta))
    batch = simulation.model.bind(pi.SceneBatch.from_scenes([scene])).failure  # hinge's view
    theta1 = batch.theta1[0]
    release = failed[np.argmax(t.obliquity[failed] > theta1)]
    moments = [
        (failed[0], "failure onset: β = 2α* held"),
        (release, "θ reaches θ1: β starts to shrink"),
        (failed[-1], "perforation"),
    ]
    h = batch.failure_plane_depth[0]
    fig, axes = style.figure(1, 3, figsize=(13, 4.6))
    rs = SPHERE.radius / mm
    circle = np.linspace(0, 2 * np.pi, 241)
    for ax, (i, title) in zip(axes, moments, strict=True):
        y, x, theta = t.lateral[i] / mm, (t.penetration[i] - SPHERE.radius) / mm, t.obliquity[i]
        area, incidence = hinge.finger(np.array([theta]), beta[i : i + 1], batch)
        phi = theta - incidence[0]  # the finger force's line, from the plate normal
        ax.axhline(0.0, color="k", lw=1)
        ax.axhline(h / mm, color="0.4", ls="--", lw=0.8)
        ax.text(y + 1.3 * rs, h / mm, " failure plane h", va="bottom", fontsize=8, color="0.3")
        ax.plot(y + rs * np.sin(circle), x + rs * np.cos(circle), color="0.5", lw=0.8)
        arc = np.linspace(phi - 0.5 * beta[i], phi + 0.5 * beta[i], 50)
        ax.plot(
            y + rs * np.sin(arc),
            x + rs * np.cos(arc),
            color="C3",
            lw=4,
            label="finger contact (width β)",
        )
        edge = theta - 0.5 * np.pi  # last point of contact: edge of the forward hemisphere
        ax.plot([y, y + rs * np.sin(edge)], [x, x + rs * np.cos(edge)], color="C2", lw=1)
        tip = (y + rs * np.sin(phi), x + rs * np.cos(phi))
        ax.annotate(
            "",
            xy=(y + 0.35 * rs * np.sin(phi), x + 0.35 * rs * np.cos(phi)),
            xytext=tip,
            arrowprops={"arrowstyle": "->", "color": "C3", "lw": 1.5},
        )
        ax.annotate(
            "",
            xy=(y + 1.6 * rs * np.sin(theta), x + 1.6 * rs * np.cos(theta)),
            xytext=(y, x),
            arrowprops={"arrowstyle": "->", "color": "C0"},
        )
        ax.plot(
            t.lateral[: i + 1] / mm,
            (t.penetration[: i + 1] - SPHERE.radius) / mm,
            ":",
            color="C0",
            lw=0.8,
        )
        ax.set_title(
            f"{title}\nθ = {math.degrees(theta):.1f}°, β = {math.degrees(beta[i]):.1f}°, "
            f"ψ″ = {math.degrees(incidence[0]):.1f}°",
            fontsize=9,
        )
        ax.set_aspect("equal")
        ax.set_xlim(y - 2.2 * rs, y + 2.2 * rs)
        ax.set_ylim(x + 2 * rs, min(-0.5, x - 1.6 * rs))
        ax.set_xlabel("along the plate [mm]")
    axes[0].set_ylabel("depth [mm]")
    axes[0].legend(loc="lower left", fontsize=8)
    fig.suptitle(
        "Hinge failure, SAE 1010 1.47 mm, 500 m/s at 30°: finger force F″ (red arrow), "
        "velocity (blue), edge of the forward hemisphere (green)",
        fontsize=10,
    )
    path = out / "hinge_geometry.png"
    saving.save(fig, str(path))
    return path


def outcome_map(out: Path) -> Path:
    from plateimpact.figures.limits_and_maps import plot_outcome_map  # noqa: PLC0415

    plate = presets.plate("2024-T3/3.18")
    found = limits.outcome_map(pi.Simulation.from_names(), SPHERE, plate)
    path = out / "outcome_map_2024T3_3.18mm.png"
    saving.save(plot_outcome_map([("2024-T3, 3.18 mm", found)]), str(path))
    return path


def limit_curves(out: Path) -> Path:
    from plateimpact.figures.limits_and_maps import plot_limit_curves  # noqa: PLC0415

    simulation = pi.Simulation.from_names()
    maps = [
        (name, limits.outcome_map(simulation, SPHERE, presets.plate(name)))
        for name in presets.PLATES
    ]
    path = out / "limit_curves.png"
    saving.save(plot_limit_curves(maps), str(path))
    return path


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--out", type=Path, default=Path("docs/figures"))
    args = parser.parse_args()
    args.out.mkdir(parents=True, exist_ok=True)
    for make in (figure_30_31, figure_35, hinge_geometry, outcome_map, limit_curves):
        print(make(args.out))


if __name__ == "__main__":
    main()
