"""The thermostat's target lowered by the modified energy: what a user sets as ``temperature=`` so that a
splitting with the thermostat at the ends of its step samples configurations at the temperature meant.

A splitting step conserves a modified energy, not the energy; stochastic velocity rescaling pins the kinetic energy
at the event point, so at a step h the configurations sample a temperature higher by a relative
g = c_T(s) h^2 <w^2> (:mod:`openmm_symprk.methods.shadow`: c_T of the method's kick/drift sequence at the event
point s, <w^2> = <F.M^-1.F>/(N_f kT) the system's mean square frequency,
:func:`openmm_symprk.systems.frequencies.mean_square_frequency`).  Asking for T (1 - g) removes it to first order: in SPC/E water the potential energy's
bias of `omelyan-2` at 4-6 fs falls from +0.08-0.11 to within 1 SE of the reference (docs/fidelity.md).
"""
from __future__ import annotations

import openmm.unit as unit

from ..methods.resolved import resolve, thermostat_position_for
from ..methods.shadow import shadow_target
from ..support.errors import InputError
from ..systems.frequencies import mean_square_frequency
from ..systems.prepare import positions_nm
from .base import step_size_in_ps

__all__ = ["lowered_target", "LoweredTargetWarning", "WARN_ABOVE", "REFUSE_ABOVE"]

#: Relative lowerings above which the first-order correction is doubtful (a warning) or meaningless (an error): in
#: water the method's steps lower 300 K by 0.1-1 % (Verlet at 3 fs: 1.0 %); unequilibrated configurations (large
#: forces) or a step near the stability limit give far more.
WARN_ABOVE, REFUSE_ABOVE = 0.02, 0.05


class LoweredTargetWarning(UserWarning):
    """The lowered target is more than :data:`WARN_ABOVE` below the temperature asked for."""


def lowered_target(method: str, step_size, system, configurations, temperature, thermostat_position: str = "auto"):
    """The target temperature that makes ``method`` at ``step_size`` with the thermostat at ``thermostat_position``
    sample ``system``'s configurations at ``temperature`` (module docstring).  ``configurations``: positions (nm,
    or a list of them) from an equilibrated run, over which <w^2> is averaged (not a builder's positions, whose forces
    are large, nor minimised ones, whose forces are nearly zero: a lowering beyond :data:`REFUSE_ABOVE` is refused,
    one beyond :data:`WARN_ABOVE` warns).  Returns a Quantity in kelvin where
    ``temperature`` is one, else kelvin as a float."""
    h = step_size_in_ps(step_size)
    kelvin = temperature.value_in_unit(unit.kelvin) if unit.is_quantity(temperature) else float(temperature)
    if not kelvin > 0:
        raise InputError(f"temperature {temperature!r}: a positive temperature, e.g. 300*unit.kelvin")
    resolved = resolve(method, constraints=system.getNumConstraints() > 0)
    if not resolved.is_splitting or resolved.is_mts:
        raise InputError(f"method {method!r}: the lowered target is defined for kick/drift splittings on one time "
                         f"scale (e.g. 'verlet', 'omelyan-2', 'predescu-3'), not for general PRK tableaux or multiple "
                         f"time stepping")
    position = thermostat_position_for(resolved, thermostat_position)
    configurations = _in_nm(configurations)
    omega2 = mean_square_frequency(system, configurations, kelvin)["all"]  # 1/ps^2
    factor = shadow_target(resolved.splitting.steps, position, h * h * omega2)
    what = (f"lowered_target({method!r}, {h * 1000:g} fs): the configurations' <w^2> = {omega2:.4g} ps^-2 lowers "
            f"{kelvin:g} K by {100 * (1 - factor):.2f} %")
    if abs(1 - factor) > REFUSE_ABOVE:
        raise InputError(f"{what}, beyond the {100 * REFUSE_ABOVE:g} % where a first-order correction means anything: "
                         f"give configurations from an equilibrated run (a builder's positions carry large forces, "
                         f"minimised ones almost none: both misstate <w^2>), "
                         f"or a smaller step (in water the method's usable steps lower it by 0.1-1 %)")
    if abs(1 - factor) > WARN_ABOVE:
        import warnings

        warnings.warn(f"{what}: more than {100 * WARN_ABOVE:g} %, where the first-order correction is doubtful; check "
                      f"that the configurations are equilibrated and the step well inside the method's stability",
                      LoweredTargetWarning, stacklevel=2)
    lowered = kelvin * factor
    return lowered * unit.kelvin if unit.is_quantity(temperature) else lowered


def _in_nm(configurations) -> list:
    """``configurations`` (one set of positions, or a list of them; Quantities or numbers in nm) as a list of (N, 3)
    arrays in nm (:func:`openmm_symprk.systems.prepare.positions_nm` each)."""
    import numpy as np

    if unit.is_quantity(configurations):
        return [positions_nm(configurations)]
    if not len(configurations):
        raise InputError("lowered_target: no configuration given; pass the positions of an equilibrated run (one set "
                         "of positions, or a list of them)")
    first = configurations[0]
    if np.ndim(first.value_in_unit(unit.nanometer) if unit.is_quantity(first) else first) <= 1:
        return [positions_nm(configurations)]  # one configuration: a list of positions
    return [positions_nm(x) for x in configurations]
