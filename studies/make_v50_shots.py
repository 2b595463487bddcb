"""Synthetic go/no-go shots for trying ``plateimpact v50``: a V50 firing series on the
1.47-mm SAE 1010 plate at 0 and 45 degrees, with a stated noise model.

    python studies/make_v50_shots.py [--seed 20240320] [--per-obliquity 24]
        [--out-dir studies/data]

writes ``gonogo_SAE1010_1.47mm.csv``, saying in its header that it is synthetic and how
it was made. Plates and spheres vary, so a real series has a zone of mixed results; here
each shot perforates if its impact speed exceeds a ballistic limit drawn afresh from
N(V_model, σ²), V_model the model's ballistic limit at that obliquity (plateimpact.limits)
and σ = 15 m/s: P(perforation) = Φ((v − V_model)/σ), a probit curve with V50 = V_model.
The speeds follow an up-and-down series, as V50 firings do: the first at V_model + 30
m/s, each next one 10 m/s slower after a perforation and 10 m/s faster after none; each
recorded with 3 m/s N(0, 1) of measurement noise, rounded to 0.1 m/s. Same seed, same file.
"""

from __future__ import annotations

import argparse
from pathlib import Path

import numpy as np

import plateimpact as pi
from plateimpact import presets
from plateimpact.units import deg

HERE = Path(__file__).resolve().parent
PLATE_NAME = "SAE1010/1.47"
OBLIQUITIES_DEG = (0.0, 45.0)
#: The noise model (module text) [m/s]: the spread of the ballistic limit, the first
#: shot above the model's limit, the up-and-down step, the speed measurement noise.
LIMIT_SIGMA, FIRST_ABOVE, STEP, SPEED_SIGMA = 15.0, 30.0, 10.0, 3.0
NAME = "gonogo_SAE1010_1.47mm.csv"


def model_limits() -> list[float]:
    """The model's ballistic limit [m/s] at each obliquity (default model and sphere)."""
    found = pi.limits.along_speed(
        pi.Simulation.from_names(), presets.DEFAULT_SPHERE, presets.plate(PLATE_NAME),
        np.array(OBLIQUITIES_DEG) * deg, (50.0, 2000.0),
    )  # fmt: skip
    return [float(line.ballistic_limit) for line in found.lines]


def up_and_down(rng: np.random.Generator, limit: float, count: int) -> list[tuple[float, bool]]:
    """``count`` shots (recorded speed [m/s], perforated) of one series (module text)."""
    shots, speed = [], limit + FIRST_ABOVE
    for _ in range(count):
        perforated = bool(speed > rng.normal(limit, LIMIT_SIGMA))
        shots.append((round(speed + rng.normal(0.0, SPEED_SIGMA), 1), perforated))
        speed += -STEP if perforated else STEP
    return shots


def main() -> None:
    parser = argparse.ArgumentParser(description=(__doc__ or "").splitlines()[0])
    parser.add_argument("--seed", type=int, default=20240320, help="random seed")
    parser.add_argument("--per-obliquity", type=int, default=24, help="shots per obliquity")
    parser.add_argument("--out-dir", type=Path, default=HERE / "data", help="where to write")
    args = parser.parse_args()
    rng = np.random.default_rng(args.seed)
    limits = model_limits()
    lines = [
        "# SYNTHETIC DATA, NOT FIRINGS: go/no-go shots drawn from a probit curve centred on "
        "plateimpact's ballistic limit.",
        f"# Made by studies/make_v50_shots.py --seed {args.seed} --per-obliquity "
        f"{args.per_obliquity}; {PLATE_NAME} (Table 1, plugging), default sphere, dopri5.",
        "# Model ballistic limits V_model: "
        + ", ".join(
            f"{v:.2f} m/s at {o:g} deg" for o, v in zip(OBLIQUITIES_DEG, limits, strict=True)
        )
        + f"; each shot perforates if its speed exceeds N(V_model, {LIMIT_SIGMA:g}^2) m/s;",
        f"# up and down from V_model + {FIRST_ABOVE:g} m/s in steps of {STEP:g} m/s; recorded "
        f"speed + {SPEED_SIGMA:g} m/s N(0,1), rounded to 0.1.",
        "impact_speed_m_s,impact_obliquity_deg,perforated,source",
    ]
    for obliquity, limit in zip(OBLIQUITIES_DEG, limits, strict=True):
        for speed, perforated in up_and_down(rng, limit, args.per_obliquity):
            lines.append(f"{speed},{obliquity:g},{int(perforated)},synthetic")
    path = args.out_dir / NAME
    path.write_text("\n".join(lines) + "\n")
    print(f"wrote {len(lines) - 5} shots to {path}")


if __name__ == "__main__":
    main()
