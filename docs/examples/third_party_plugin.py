"""
A third-party plug-in, registered and run
=========================================

A resistance law that is not the report's, written as a third-party package would write
it (docs/plugins.md): a class of declarations and one pure function on arrays, and the
``plateimpact_register`` hook that registers it. Here the hook is handed to
:func:`plateimpact.load_registry` directly; an installed package names its module in the
``plateimpact`` entry-point group instead, and every command then finds it too.

The law is eq 1 with a term linear in the speed into the plate, a viscous drag:
σ = a + d V cos ψ + b V² cos² ψ. It brings its own plate constant, ``d``; with d = 0 it
is eq 1 exactly, which the example checks before it uses it.
"""

# %%
# The plug-in
# -----------
# ``plate_constants`` declares what it reads from the plate: the report's ``a`` and ``b``
# (the built-ins' declarations, so that they mean the same to every law) and its own
# ``d``, with its SI unit, range and default. ``version`` is recorded with every run:
# change it when the results change, and a resumed study refuses runs made before.
from typing import final

import attrs
import numpy as np

import plateimpact as pi
from plateimpact import presets
from plateimpact.figures import style
from plateimpact_plugins.report import DENSITY_B, STRENGTH_A

VISCOUS_D = pi.Parameter(
    "viscous_d",
    "coefficient d of the viscous term d V cos psi",
    "kg/m^2/s",
    pi.Range(0.0),
    default=0.0,
    short="d",
)


@final
@attrs.frozen
class ViscousPoncelet(pi.ResistanceLaw):
    """σ = a + d V cos ψ + b V² cos² ψ [N/m²]."""

    name = "viscous-poncelet"
    version = "1"
    plate_constants = (STRENGTH_A, DENSITY_B, VISCOUS_D)

    def stress(self, speed: np.ndarray, incidence: np.ndarray, scenes: pi.SceneBatch) -> np.ndarray:
        normal_speed = np.maximum(speed * np.cos(incidence), 0.0)  # no pull on the way out
        return scenes.a + (scenes.viscous_d + scenes.b * normal_speed) * normal_speed


class ThirdPartyPackage:
    """What the package's module holds for plateimpact: its one hook."""

    @staticmethod
    @pi.hookimpl
    def plateimpact_register(registry: pi.PluginRegistry) -> None:
        registry.add(ViscousPoncelet)


# %%
# Registered beside the installed plug-ins
# ----------------------------------------
registry = pi.load_registry(plugins=[ThirdPartyPackage])
print("resistance laws:", registry.names("resistance"))
print("its constant:   ", VISCOUS_D.key, "-", VISCOUS_D.help())

# %%
# With d = 0 it is eq 1
# ---------------------
# The same scenes through the built-in ``poncelet`` and through the new law with d = 0
# (the declared default): the same outcomes, the same exit speeds to the integrator's
# tolerance.
sphere = presets.DEFAULT_SPHERE
plate = presets.plate("2024-T3/3.18")
speeds = np.linspace(100.0, 1500.0, 57)
batch = pi.SceneBatch.grid(sphere, plate, speeds, np.radians([0.0, 45.0]))
builtin = pi.Simulation.from_names("poncelet", registry=registry).run_batch(batch)
viscous = pi.Simulation.from_names("viscous-poncelet", registry=registry)
same = viscous.run_batch(batch)
assert np.array_equal(same.outcome, builtin.outcome)
difference = np.max(np.abs(same.exit_speed - builtin.exit_speed))
print(f"largest exit-speed difference: {difference:.2g} m/s")

# %%
# A plate with a viscous term
# ---------------------------
# ``d`` is a plate constant like ``a`` and ``b``: set it on the plate (a plate file's key
# is ``d``, a study archive's column ``viscous_d``). The slower the sphere comes out,
# the more the linear term adds to the resistance; the ballistic limit at normal
# incidence (located to 0.01 m/s by :mod:`plateimpact.limits`) rises with it.
fig, ax = style.figure(figsize=(7.2, 3.6), layout="constrained")
for d, line in zip((0.0, 2e5, 5e5), ("-", "--", ":"), strict=True):
    viscous_plate = plate.with_constants(viscous_d=d)
    normal = pi.SceneBatch.grid(sphere, viscous_plate, speeds, [0.0])
    results = viscous.run_batch(normal)
    perforated = results.outcome == pi.Outcome.PERFORATION
    ax.plot(speeds[perforated], results.exit_speed[perforated], line, color="k",
            label=f"d = {d:.0e} kg/(m² s)")  # fmt: skip
    found = pi.limits.along_speed(viscous, sphere, viscous_plate, [0.0], (50.0, 2000.0))
    print(f"d = {d:.0e} kg/(m² s): ballistic limit {found.lines[0].ballistic_limit:.2f} m/s")
ax.set_xlabel("impact speed [m/s]")
ax.set_ylabel("exit speed [m/s]")
ax.set_title("2024-T3, 3.18 mm, normal incidence: perforations only")
ax.legend(loc="upper left")
fig
