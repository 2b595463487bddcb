"""The elementary functions the formulas call: √, arccos, sin, cos, and sin and cos at once.

On numbers and arrays in Python (the numpy path) they are numpy's ufuncs. Compiled code
calls branch-free polynomial versions instead (``plateimpact.solve.compiled.elementary``,
fdlibm's coefficients, within an ulp or two of numpy's): a loop over scenes that calls the
C library's ``acos`` or ``sincos`` cannot be vectorised, one that evaluates polynomials
can, so lanes of scenes evaluate their forces in one SIMD pass (docs/integrators.md,
"lanes"). Formulas, the core's and a plug-in's kernels alike, call these rather than
``np.sin`` and friends to be vectorised on the compiled path; with numpy's they still run,
a scene at a time.
"""

from __future__ import annotations

from typing import Any

import numpy as np

#: The implementations on arrays: numpy's ufuncs, unless replaced by the compiled
#: path's own (``plateimpact.solve.compiled.elementary.in_numpy_path()``, which the
#: tests use to compare the two paths with the same functions).
IMPLEMENTATIONS: dict[str, Any] = {"arccos": np.arccos, "sin": np.sin, "cos": np.cos}


def arccos(x: Any) -> Any:
    """arccos x [rad], in [0, π], for x in [−1, 1]."""
    return IMPLEMENTATIONS["arccos"](x)


def sqrt(x: Any) -> Any:
    """√x, x >= 0 (correctly rounded everywhere)."""
    return np.sqrt(x)


def sin(x: Any) -> Any:
    """sin x, x [rad]."""
    return IMPLEMENTATIONS["sin"](x)


def cos(x: Any) -> Any:
    """cos x, x [rad]."""
    return IMPLEMENTATIONS["cos"](x)


def sincos(x: Any) -> tuple[Any, Any]:
    """(sin x, cos x), x [rad]: compiled, one range reduction for both."""
    return IMPLEMENTATIONS["sin"](x), IMPLEMENTATIONS["cos"](x)
