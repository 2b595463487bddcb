"""Figures 25–31: the 3.18-mm 2024-T3 plate at 0, 30, 45 and 60°, and the comparison of
Figures 30–31 with an "extremely large" P*: a plate that never fails (``intact``), i.e.
the thick-plate behaviour of the same sphere and material.

    python studies/fig25_31_2024t3_3_18mm.py [--out DIR]
    plateimpact compare DIR/2024-T3_3.18mm.h5 plugging large-pstar
"""

from __future__ import annotations

import plateimpact as pi

try:
    from ._family import SPEEDS, main
except ImportError:  # run as a script
    from _family import SPEEDS, main


def study() -> pi.Study:
    return pi.Study.grid(
        "2024-T3_3.18mm",
        plates=["2024-T3/3.18"],
        obliquities_deg=[0, 30, 45, 60],
        speeds=SPEEDS,
        variants=[pi.Variant("plugging"), pi.Variant("large-pstar", failure="intact")],
        description="Figures 25-31: 3.18-mm 2024-T3, plugging vs an extremely large P*",
    )


if __name__ == "__main__":
    main(study())
