"""Branch-free arccos, sin and cos for compiled code: the implementations numba uses for
:mod:`plateimpact.model.elementary` (registered on import).

Plain arithmetic and selects only (the coefficients are fdlibm's, as in musl), so that a
loop over lanes of scenes that calls them is vectorised by LLVM; the C library's
functions are calls that stop it. Accurate to about one ulp: arccos on [−1, 1] (NaN
outside), sin and cos for |x| <= 8e5 rad, beyond which the two-part reduction by π/2 is
no longer exact and they return NaN (the model's angles lie in [−π, 2π]).
"""

from __future__ import annotations

from typing import Any

import numpy as np
from llvmlite import ir
from numba import types
from numba.extending import intrinsic, overload, register_jitable

from ...model import elementary

_PIO2_HI, _PIO2_LO = 1.57079632679489655800e00, 6.12323399573676603587e-17
_PI = 3.14159265358979311600e00
# arcsin's rational approximation R(z) = z P(z) / Q(z) on [0, 1/4] (fdlibm e_asin.c)
_P = (
    1.66666666666666657415e-01,
    -3.25565818622400915405e-01,
    2.01212532134862925881e-01,
    -4.00555345006794114027e-02,
    7.91534994289814532176e-04,
    3.47933107596021167570e-05,
)
_Q = (
    -2.40339491173441421878e00,
    2.02094576023350569471e00,
    -6.88283971605453293030e-01,
    7.70381505559019352791e-02,
)
# sin and cos on [−π/4, π/4] (fdlibm k_sin.c, k_cos.c)
_S = (
    -1.66666666666666324348e-01,
    8.33333333332248946124e-03,
    -1.98412698298579493134e-04,
    2.75573137070700676789e-06,
    -2.50507602534068634195e-08,
    1.58969099521155010221e-10,
)
_C = (
    4.16666666666666019037e-02,
    -1.38888888888741095749e-03,
    2.48015872894767294178e-05,
    -2.75573143513906633035e-07,
    2.08757232129817482790e-09,
    -1.13596475577881948265e-11,
)
_INV_PIO2 = 6.36619772367581382433e-01
_PIO2_1, _PIO2_1T = 1.57079632673412561417e00, 6.07710050650619224932e-11  # π/2: 33 bits + rest
_LARGEST_QUADRANT = 2.0**19  # k π/2 with |k| below this is exact in two parts


@intrinsic
def _llvm_sqrt(typingctx: Any, x: Any) -> Any:
    """LLVM's sqrt instruction: numba lowers np.sqrt to the C library's ``sqrt`` (errno),
    a call that stops vectorisation."""

    def codegen(context: Any, builder: Any, signature: Any, args: Any) -> Any:
        function = builder.module.declare_intrinsic("llvm.sqrt", [ir.DoubleType()])
        return builder.call(function, args)

    return types.float64(types.float64), codegen


@register_jitable(_nrt=False)
def sqrt_branch_free(x: float) -> float:
    """√x [NaN for x < 0]."""
    return _llvm_sqrt(x)  # type: ignore[call-arg,unused-ignore]  # numba adds the typing context


@register_jitable(_nrt=False)
def arccos_branch_free(x: float) -> float:
    """arccos x [rad] (fdlibm e_acos.c, its three ranges chosen by selects)."""
    ax = np.abs(x)
    big = ax > 0.5
    z = (1.0 - ax) * 0.5 if big else x * x
    p = z * (_P[0] + z * (_P[1] + z * (_P[2] + z * (_P[3] + z * (_P[4] + z * _P[5])))))
    q = 1.0 + z * (_Q[0] + z * (_Q[1] + z * (_Q[2] + z * _Q[3])))
    r = p / q
    s = sqrt_branch_free(z)
    middle = _PIO2_HI - (x - (_PIO2_LO - x * r))
    near_one = 2.0 * (s + s * r)
    near_minus_one = _PI - 2.0 * (s + (r * s - _PIO2_LO))
    outer = near_one if x > 0.0 else near_minus_one
    return outer if big else middle


@register_jitable(_nrt=False)
def sincos_branch_free(x: float) -> tuple[float, float]:
    """(sin x, cos x), x [rad]: x reduced by the nearest multiple k of π/2, the
    polynomials on [−π/4, π/4], then rotated by k quarter turns (selects)."""
    k = np.rint(x * _INV_PIO2)
    r = (x - k * _PIO2_1) - k * _PIO2_1T
    z = r * r
    w = z * z
    rs = _S[1] + z * (_S[2] + z * _S[3]) + z * w * (_S[4] + z * _S[5])
    s = r + z * r * (_S[0] + z * rs)
    rc = z * (_C[0] + z * (_C[1] + z * _C[2])) + w * w * (_C[3] + z * (_C[4] + z * _C[5]))
    half = 0.5 * z
    one_minus = 1.0 - half
    c = one_minus + (((1.0 - one_minus) - half) + z * rc)
    quarter = k - 4.0 * np.floor(0.25 * k)  # 0, 1, 2 or 3, kept a float: it vectorises
    # One comparison per select (a chain of them compiles to branches LLVM keeps):
    # odd quarters swap sin and cos; sin is negative in quarters 2, 3, cos in 1, 2.
    odd = np.abs(quarter - 2.0) == 1.0
    sin_base = c if odd else s
    cos_base = s if odd else c
    sin = -sin_base if quarter >= 2.0 else sin_base
    cos = -cos_base if np.abs(quarter - 1.5) < 1.0 else cos_base
    exact = np.abs(k) < _LARGEST_QUADRANT  # False also for NaN and inf
    return (sin if exact else np.nan), (cos if exact else np.nan)


def _sin_of(x: float) -> float:
    return sincos_branch_free(x)[0]


def _cos_of(x: float) -> float:
    return sincos_branch_free(x)[1]


def in_numpy_path() -> None:
    """Make the numpy path call these very functions (as numpy ufuncs compiled by
    ``numba.vectorize``) instead of numpy's, for this process: the two paths then share
    their elementary functions bit for bit, as the test comparing them step for step
    needs. Not for production runs: numpy's own are faster on arrays."""
    from numba import vectorize  # noqa: PLC0415

    signature = ["float64(float64)"]
    elementary.IMPLEMENTATIONS.update(
        arccos=vectorize(signature)(arccos_branch_free),
        sin=vectorize(signature)(_sin_of),
        cos=vectorize(signature)(_cos_of),
    )


def _floats(x: Any) -> bool:
    return isinstance(x, types.Float)


@overload(elementary.arccos)
def _arccos(x: Any) -> Any:
    def implementation(x: Any) -> Any:
        return arccos_branch_free(x)

    return implementation if _floats(x) else None


@overload(elementary.sqrt)
def _sqrt(x: Any) -> Any:
    def implementation(x: Any) -> Any:
        return sqrt_branch_free(x)

    return implementation if _floats(x) else None


@overload(elementary.sincos)
def _sincos(x: Any) -> Any:
    def implementation(x: Any) -> Any:
        return sincos_branch_free(x)

    return implementation if _floats(x) else None


@overload(elementary.sin)
def _sin(x: Any) -> Any:
    def implementation(x: Any) -> Any:
        return sincos_branch_free(x)[0]

    return implementation if _floats(x) else None


@overload(elementary.cos)
def _cos(x: Any) -> Any:
    def implementation(x: Any) -> Any:
        return sincos_branch_free(x)[1]

    return implementation if _floats(x) else None
