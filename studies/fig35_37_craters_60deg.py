"""Figures 35–37: crater sections at 60° in the 9.53-mm 6061-T6, 6.35-mm and 3.18-mm
2024-T3 plates. The report's figures survive only as speed labels: 0.263 and 0.737 km/s
(Figure 35), 0.729 km/s (Figure 36, within 1% of 0.737) and 0.474 km/s (Figure 37); 150
and 1000 m/s are added to span ricochet to perforation on every plate.

    python studies/fig35_37_craters_60deg.py [--out DIR]
    plateimpact plot DIR/craters_60deg.h5 --run default --kind trajectory --out paths.png
"""

from __future__ import annotations

import plateimpact as pi

try:
    from ._family import main
except ImportError:  # run as a script
    from _family import main

CRATER_SPEEDS = [150.0, 263.0, 474.0, 737.0, 1000.0]


def study() -> pi.Study:
    return pi.Study.grid(
        "craters_60deg",
        plates=["6061-T6/9.53", "2024-T3/6.35", "2024-T3/3.18"],
        obliquities_deg=[60],
        speeds=CRATER_SPEEDS,
        variants=pi.Variant("default"),
        description="Figures 35-37: predicted crater sections at 60 deg",
    )


if __name__ == "__main__":
    main(study(), craters=True)
