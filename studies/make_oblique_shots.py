"""Synthetic oblique shot data for trying ``validate``, ``v50`` and the P* fits: the
model's own outcomes, residual speeds and exit obliquities at 0, 30, 45 and 60 degrees on
the 1.47-mm SAE 1010 plate, with a stated noise model.

    python studies/make_oblique_shots.py [--seed 20240318] [--per-obliquity 20]
        [--out-dir studies/data]

writes two files, each saying in its header that it is synthetic and how it was made:

* ``oblique_SAE1010_1.47mm_pstar4.6.csv``: plugging at Table 1's P* = 4.6 mm;
* ``oblique_SAE1010_1.47mm_variable_pstar.csv``: the ``variable-pstar`` plug-in with the
  report's SAE 1010 table (P* by obliquity for the ricochet and the perforation range).

At each obliquity the true impact speeds run evenly from 0.6 to 1.6 times the model's
ballistic limit there (``plateimpact.limits``), each moved by a uniform ±5 m/s. The
outcome is the model's at the true speed; the file records the impact speed with
Gaussian noise of σ = 3 m/s, the residual speed (perforations and ricochets) times
1 + 0.03 N(0, 1), the exit obliquity plus 2° N(0, 1), all rounded to 0.1; each shot, with
probability 1/4, records only whether it perforated (go/no-go). Same seed, same files.
"""

from __future__ import annotations

import argparse
from pathlib import Path

import attrs
import numpy as np

import plateimpact as pi
from plateimpact import presets
from plateimpact.units import deg, g, mm

HERE = Path(__file__).resolve().parent
PLATE_NAME = "SAE1010/1.47"
SPHERE = presets.DEFAULT_SPHERE
OBLIQUITIES_DEG = (0.0, 30.0, 45.0, 60.0)
#: The noise model (module text): impact speed [m/s], residual speed [-], exit
#: obliquity [deg], the chance that a shot is go/no-go only, the jitter of the true speeds [m/s].
SPEED_SIGMA, RESIDUAL_SIGMA, EXIT_SIGMA_DEG, GO_NO_GO, JITTER = 3.0, 0.03, 2.0, 0.25, 5.0
#: (file name, failure model) of each file.
FILES = (
    ("oblique_SAE1010_1.47mm_pstar4.6.csv", "plugging"),
    ("oblique_SAE1010_1.47mm_variable_pstar.csv", "variable-pstar"),
)


def rounded(shots: pi.Shots) -> pi.Shots:
    """The recorded values to 0.1 m/s and 0.1 deg, as a range writes them; a perforation
    keeps a residual speed of at least 0.1 m/s."""
    residual = np.round(shots.residual_speed, 1)
    residual = np.where(shots.perforated, np.maximum(residual, 0.1), residual)
    return attrs.evolve(
        shots,
        impact_speed=np.round(shots.impact_speed, 1),
        residual_speed=np.minimum(residual, np.round(shots.impact_speed, 1)),
        exit_obliquity=np.round(shots.exit_obliquity / deg, 1) * deg,
        notes=("synthetic",) * len(shots),
    )


def make_shots(failure: str, seed: int, per_obliquity: int) -> pi.Shots:
    """The shots of one file (see the module's text)."""
    plate = presets.plate(PLATE_NAME)
    simulation = pi.Simulation.from_names(failure=failure)
    obliquities = np.array(OBLIQUITIES_DEG) * deg
    limits = pi.limits.along_speed(simulation, SPHERE, plate, obliquities, (50.0, 2000.0))
    rng = np.random.default_rng(seed)
    speeds = np.concatenate(
        [np.linspace(0.6, 1.6, per_obliquity) * line.ballistic_limit for line in limits.lines]
    )
    speeds += rng.uniform(-JITTER, JITTER, speeds.size)
    shots = pi.synthetic_oblique_shots(
        simulation, SPHERE, plate, speeds, np.repeat(obliquities, per_obliquity), rng,
        speed_noise=SPEED_SIGMA, residual_noise=RESIDUAL_SIGMA,
        exit_obliquity_noise=EXIT_SIGMA_DEG * deg, go_no_go_fraction=GO_NO_GO,
    )  # fmt: skip
    return rounded(shots)


def header(failure: str, command_seed: int, seed: int, per_obliquity: int) -> list[str]:
    """The comment lines that say what the file is."""
    plate = presets.plate(PLATE_NAME)
    pstar = (
        f"P* = {plate.critical_penetration / mm:g} mm (Table 1), plugging"
        if failure == "plugging"
        else "variable P* (the variable-pstar plug-in's SAE 1010 table, obliquity_deg,"
        "ricochet_pstar_mm,perforation_pstar_mm,transition_start_m_s,transition_end_m_s: "
        "0,4.6,4.6,300,330; 45,3.5,4.4,330,420; 60,3.0,3.8,430,550)"
    )
    return [
        "SYNTHETIC DATA, NOT FIRINGS: outcomes and speeds computed by plateimpact's model, "
        "with noise.",
        f"Made by studies/make_oblique_shots.py --seed {command_seed} --per-obliquity "
        f"{per_obliquity} (this file: seed {seed})",
        f"{PLATE_NAME} of NWC TP 5844 Table 1: a = {plate.a:.4g} N/m^2, b = {plate.b:.4g} "
        f"kg/m^3, alpha* = {plate.failure_angle / deg:g} deg; {pstar};",
        f"sphere radius {SPHERE.radius / mm:g} mm, mass {SPHERE.mass / g:.4f} g; dopri5 at "
        f"its default rtol. At {', '.join(f'{o:g}' for o in OBLIQUITIES_DEG)} deg, true "
        "speeds 0.6-1.6 x the model's ballistic limit (+-5 m/s uniform);",
        f"outcome: the model's at the true speed; recorded impact speed + {SPEED_SIGMA:g} "
        f"m/s N(0,1), residual speed x (1 + {RESIDUAL_SIGMA:g} N(0,1)), exit obliquity + "
        f"{EXIT_SIGMA_DEG:g} deg N(0,1), rounded to 0.1;",
        f"each shot, with probability {GO_NO_GO:g}, records only perforated 0/1.",
    ]


def main() -> None:
    parser = argparse.ArgumentParser(description=(__doc__ or "").splitlines()[0])
    parser.add_argument("--seed", type=int, default=20240318, help="random seed")
    parser.add_argument("--per-obliquity", type=int, default=20, help="shots per obliquity")
    parser.add_argument("--out-dir", type=Path, default=HERE / "data", help="where to write")
    args = parser.parse_args()
    for offset, (name, failure) in enumerate(FILES):
        seed = args.seed + offset
        shots = make_shots(failure, seed, args.per_obliquity)
        path = args.out_dir / name
        path.write_text(shots.to_csv_text(header(failure, args.seed, seed, args.per_obliquity)))
        print(
            f"wrote {len(shots)} shots ({int(shots.perforated.sum())} perforating, "
            f"{int((shots.outcome == 0).sum())} go/no-go) to {path}"
        )


if __name__ == "__main__":
    main()
