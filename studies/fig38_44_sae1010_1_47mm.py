"""Figures 38–44: mild steel (SAE 1010, 1.47 mm) at 0, 30, 45 and 60°, with the plate's
constant P* = 4.6 mm and with the report's variable P* (docs/variable-pstar.md).

    python studies/fig38_44_sae1010_1_47mm.py [--out DIR]
    plateimpact compare DIR/SAE1010_1.47mm.h5 constant-pstar variable-pstar
"""

from __future__ import annotations

import plateimpact as pi

try:
    from ._family import SPEEDS, main
except ImportError:  # run as a script
    from _family import SPEEDS, main


def study() -> pi.Study:
    return pi.Study.grid(
        "SAE1010_1.47mm",
        plates=["SAE1010/1.47"],
        obliquities_deg=[0, 30, 45, 60],
        speeds=SPEEDS,
        variants=[
            pi.Variant("constant-pstar"),
            pi.Variant("variable-pstar", failure="variable-pstar"),
        ],
        description="Figures 38-44: 1.47-mm SAE 1010, constant vs variable P*",
    )


if __name__ == "__main__":
    main(study())
