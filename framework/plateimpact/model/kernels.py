"""The compiled path's side of the plug-in contract: what a plug-in provides to run as
compiled code, and the helpers its kernels call.

A **kernel** is a function of numbers (floats, and 1-D float arrays of per-scene
constants) written with numpy ufuncs and arithmetic only, so that numba compiles it; the
numpy path calls the same formulas on arrays (each formula exists once). The functions a
kernel calls are listed, callees first, in its module's ``KERNELS`` tuple
(:data:`plateimpact.model.geometry.KERNELS`): the compiled path registers them.

* A :class:`~plateimpact.ResistanceLaw` opts in with ``stress_kernel``:
  ``stress(speed [m/s], incidence [rad], constants) -> σ [N/m²]``, ``constants`` being
  one scene's row of :meth:`~plateimpact.model.plugin.Plugin.kernel_constants`.
* A :class:`~plateimpact.FailureModel` opts in with ``kernels``, a :class:`FailureKernels`
  whose functions take one :class:`KernelContact` (a scene's :class:`Contact` in numbers).

docs/plugins.md ("A compiled plug-in") shows one whole.
"""

from __future__ import annotations

from collections.abc import Callable
from typing import Any, NamedTuple

from .geometry import contact_surface_kernel
from .resistance import force_on_contact


class KernelContact(NamedTuple):
    """One scene at one instant, as a failure model's kernels see it (the numbers of a
    :class:`~plateimpact.Contact`).

    ``penetration`` P [m]; ``obliquity`` θ [rad], >= 0 (the mirror image of a path that
    swung across the normal); ``speed`` V [m/s]; ``obliquity_rate`` dθ/dt [rad/s] (NaN
    except in ``state_rates``); ``failure_state`` the model's state variables (1-D,
    ``len(state_names)``; zero before onset); ``constants`` the model's row of
    ``kernel_constants`` for this scene; ``radius`` Rs [m]; ``stress`` the resistance
    law's stress kernel and ``law_constants`` its row: use :func:`law_force` and
    :func:`law_stress` rather than these two.
    """

    penetration: float
    obliquity: float
    speed: float
    obliquity_rate: float
    failure_state: Any
    constants: Any
    radius: float
    stress: Any
    law_constants: Any


def law_stress(speed: float, incidence: float, contact: KernelContact) -> float:
    """σ [N/m²] of the model's resistance law at speed V [m/s] and incidence ψ [rad]
    (the kernel twin of ``contact.law.stress``)."""
    return contact.stress(speed, incidence, contact.law_constants)


def law_force(
    penetration: float, obliquity: float, speed: float, contact: KernelContact
) -> tuple[float, float]:
    """Drag and lift [N] of the model's resistance law on the contact surface below a
    plane ``penetration`` [m] above the sphere's deepest point (the kernel twin of
    ``contact.law.contact_force``, eqs 1, 22–24)."""
    return force_on_contact(
        penetration,
        obliquity,
        speed,
        contact.radius,
        contact_surface_kernel,
        contact.stress,
        contact.law_constants,
    )


def no_branch_margins(contact: KernelContact, out: Any) -> None:
    """A failure model whose force has no branch surface of its own writes none."""


def no_initial_state(contact: KernelContact, out: Any) -> None:
    """Failure state at onset: zeros (the default :meth:`FailureModel.initial_state`)."""
    for row in range(out.size):
        out[row] = 0.0


def no_state_rates(contact: KernelContact, out: Any) -> None:
    """A constant failure state (the default :meth:`FailureModel.state_rates`)."""
    for row in range(out.size):
        out[row] = 0.0


def no_force_change(contact: KernelContact) -> tuple[float, float]:
    """No force besides the relief (drag, lift [N]): a plugging plate's ``force_change``."""
    return 0.0, 0.0


class FailureKernels(NamedTuple):
    """A failure model's methods as kernels of one :class:`KernelContact`: the same
    formulas as its numpy methods, for the compiled path.

    ``force_change(contact) -> (drag [N], lift [N])``; ``perforation_margin(contact) ->
    [m]``; ``branch_margins(contact, out)`` writes its ``branch_rows`` margins into
    ``out``; ``initial_state(contact, out)`` and ``state_rates(contact, out)`` write the
    state at onset and its rates [unit/s] (``contact.obliquity_rate`` known there).

    ``relief_column``: where the plate separates along a plane (eqs 8–15), the row of
    ``kernel_constants`` holding its depth h [m]. The force change is then −F′, the
    resistance law's force on the contact surface below that plane, plus what
    ``force_change`` returns besides (the hinge's finger; :func:`no_force_change` for a
    plugging plate): the compiled path evaluates F′ for lanes of scenes together, as it
    does the intact force. −1 (the default): ``force_change`` is the whole change.
    """

    force_change: Callable[..., tuple[float, float]]
    perforation_margin: Callable[..., float]
    branch_rows: int = 0
    branch_margins: Callable[..., None] = no_branch_margins
    initial_state: Callable[..., None] = no_initial_state
    state_rates: Callable[..., None] = no_state_rates
    relief_column: int = -1

    def functions(self) -> tuple[Callable[..., Any], ...]:
        """The kernels, for the compiled path to compile."""
        return (
            self.force_change,
            self.perforation_margin,
            self.branch_margins,
            self.initial_state,
            self.state_rates,
        )


#: The functions of numbers a compiled path compiles (callees before callers).
KERNELS = (
    law_stress,
    law_force,
    no_branch_margins,
    no_initial_state,
    no_state_rates,
    no_force_change,
)
