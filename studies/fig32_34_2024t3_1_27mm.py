"""Figures 32–34: the thin 1.27-mm 2024-T3 plate at 0, 30, 45 and 60°, where failure
during ricochet gives a narrow band of slow, steep ricochets below the embedment range.

    python studies/fig32_34_2024t3_1_27mm.py [--out DIR]
"""

from __future__ import annotations

import plateimpact as pi

try:
    from ._family import SPEEDS, main
except ImportError:  # run as a script
    from _family import SPEEDS, main


def study() -> pi.Study:
    return pi.Study.grid(
        "2024-T3_1.27mm",
        plates=["2024-T3/1.27"],
        obliquities_deg=[0, 30, 45, 60],
        speeds=SPEEDS,
        variants=[pi.Variant("plugging")],
        description="Figures 32-34: 1.27-mm 2024-T3, plugging with the plate's P*",
    )


if __name__ == "__main__":
    main(study())
