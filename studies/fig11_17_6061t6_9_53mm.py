"""Figures 11–17: the thick 9.53-mm 6061-T6 plate at 0, 20, 45 and 60°.

python studies/fig11_17_6061t6_9_53mm.py [--out DIR]
"""

from __future__ import annotations

import plateimpact as pi

try:
    from ._family import SPEEDS, main
except ImportError:  # run as a script
    from _family import SPEEDS, main


def study() -> pi.Study:
    return pi.Study.grid(
        "6061-T6_9.53mm",
        plates=["6061-T6/9.53"],
        obliquities_deg=[0, 20, 45, 60],
        speeds=SPEEDS,
        variants=[pi.Variant("plugging")],
        description="Figures 11-17: 9.53-mm 6061-T6, plugging with the plate's P*",
    )


if __name__ == "__main__":
    main(study())
