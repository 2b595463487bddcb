"""Figures 18–24: the 6.35-mm 2024-T3 plate at 0, 30, 45 and 60°.

python studies/fig18_24_2024t3_6_35mm.py [--out DIR]
"""

from __future__ import annotations

import plateimpact as pi

try:
    from ._family import SPEEDS, main
except ImportError:  # run as a script
    from _family import SPEEDS, main


def study() -> pi.Study:
    return pi.Study.grid(
        "2024-T3_6.35mm",
        plates=["2024-T3/6.35"],
        obliquities_deg=[0, 30, 45, 60],
        speeds=SPEEDS,
        variants=[pi.Variant("plugging")],
        description="Figures 18-24: 6.35-mm 2024-T3, plugging with the plate's P*",
    )


if __name__ == "__main__":
    main(study())
