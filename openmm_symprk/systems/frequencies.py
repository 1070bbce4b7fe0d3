"""How fast a System's degrees of freedom move at a temperature: the mean square angular frequency <w^2> that sets
a splitting's step error (its modified energy grows as (h w)^2: :mod:`openmm_symprk.methods.shadow`).

In the canonical ensemble <F.M^-1.F> = kT <tr(M^-1 Hess V)> = kT sum_i w_i^2 for harmonic modes, so <w^2> per degree
of freedom is <F.M^-1.F> / (N_f kT), with F the force projected onto the constraints' tangent space (the part a
kick keeps after RATTLE's velocity projection), measured at equilibrium configurations.  For rigid molecules the
translational part is sum over molecules of |F_mol|^2 / M_mol (3 degrees of freedom each) and the rest is rotation.
"""
from __future__ import annotations

import numpy as np
import openmm as mm
import openmm.unit as unit

from ..physics.temperature import R_KJ
from ..support.errors import InputError
from .properties import degrees_of_freedom, masses

__all__ = ["mean_square_frequency"]



def mean_square_frequency(system: mm.System, configurations, temperature: float, molecules=None,
                          platform: str = "Reference", tolerance: float = 1e-10) -> dict:
    """{"all": <w^2> per degree of freedom (1/ps^2), "configurations": their number} over ``configurations`` (an
    iterable of positions in nm) at ``temperature`` (K), with "trans" and "rot" per degree of freedom of each kind
    where ``molecules`` (lists of particle indices, rigid) are given.  The projection onto the constraints is
    OpenMM's own (``Context.applyVelocityConstraints`` on M^-1 F)."""
    m = masses(system)
    inv = np.where(m > 0, 1.0 / np.where(m > 0, m, 1.0), 0.0)
    kt = R_KJ * float(temperature)
    n_f = degrees_of_freedom(system)
    context = mm.Context(system, mm.VerletIntegrator(0.001), mm.Platform.getPlatformByName(platform))
    total, trans, n = 0.0, 0.0, 0
    try:
        for x in configurations:
            context.setPositions(np.asarray(x))
            f = np.array(context.getState(getForces=True).getForces(asNumpy=True)
                         .value_in_unit(unit.kilojoule_per_mole / unit.nanometer))
            a = f * inv[:, None]
            if system.getNumConstraints():
                context.setVelocities(a)
                context.applyVelocityConstraints(tolerance)
                a = np.array(context.getState(getVelocities=True).getVelocities(asNumpy=True)._value)
            total += float(np.sum(m[:, None] * a * a))
            if molecules is not None:
                trans += sum(float(np.sum(f[list(g)].sum(axis=0) ** 2) / m[list(g)].sum()) for g in molecules)
            n += 1
    finally:
        del context
    if not n:
        raise InputError("no configuration given: <w^2> is an average over equilibrium configurations")
    out = {"all": total / n / (n_f * kt), "configurations": n}
    if molecules is not None:
        n_trans = 3 * len(molecules)
        out["trans"] = trans / n / (n_trans * kt)
        out["rot"] = (total - trans) / n / ((n_f - n_trans) * kt)
    return out
