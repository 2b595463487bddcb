"""Dormand–Prince 5(4): the default integrator."""

from __future__ import annotations

from typing import final

import attrs
import numpy as np

from .embedded_rk import EmbeddedRungeKutta


@final
@attrs.frozen
class DormandPrince54(EmbeddedRungeKutta):
    """Dormand & Prince (1980) 5(4) pair, FSAL, with Shampine's 4th-order dense output
    (the coefficients of scipy's RK45). Error estimate of order 4, so the step follows
    err^(−1/5). Settings (:class:`EmbeddedRungeKutta`): ``rtol`` (default 1e-8: exit speed
    within 2e-7 of the impact speed and exit obliquity within 1e-5° of the reference on
    the benchmark set, docs/integrators.md), ``max_steps``, ``fixed_step``,
    ``branch_landing``.
    """

    name = "dopri5"
    error_order = 5
    C = np.array([0, 1 / 5, 3 / 10, 4 / 5, 8 / 9, 1])
    A = np.array(
        [
            [0, 0, 0, 0, 0],
            [1 / 5, 0, 0, 0, 0],
            [3 / 40, 9 / 40, 0, 0, 0],
            [44 / 45, -56 / 15, 32 / 9, 0, 0],
            [19372 / 6561, -25360 / 2187, 64448 / 6561, -212 / 729, 0],
            [9017 / 3168, -355 / 33, 46732 / 5247, 49 / 176, -5103 / 18656],
        ]
    )
    B = np.array([35 / 384, 0, 500 / 1113, 125 / 192, -2187 / 6784, 11 / 84])
    E = np.array([-71 / 57600, 0, 71 / 16695, -71 / 1920, 17253 / 339200, -22 / 525, 1 / 40])
    P = np.array(
        [
            [1, -8048581381 / 2820520608, 8663915743 / 2820520608, -12715105075 / 11282082432],
            [0, 0, 0, 0],
            [0, 131558114200 / 32700410799, -68118460800 / 10900136933, 87487479700 / 32700410799],
            [0, -1754552775 / 470086768, 14199869525 / 1410260304, -10690763975 / 1880347072],
            [
                0,
                127303824393 / 49829197408,
                -318862633887 / 49829197408,
                701980252875 / 199316789632,
            ],
            [0, -282668133 / 205662961, 2019193451 / 616988883, -1453857185 / 822651844],
            [0, 40617522 / 29380423, -110615467 / 29380423, 69997945 / 29380423],
        ]
    )
