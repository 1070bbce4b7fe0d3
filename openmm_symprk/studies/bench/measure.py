"""Observables of one sample of a run, in float64 from the arrays OpenMM returns.

Units: nm, ps, Da, kJ/mol.  Momenta come from :mod:`openmm_symprk.physics`, constraint errors from
:mod:`openmm_symprk.systems.properties` and energy drifts from :mod:`openmm_symprk.stats`, as everywhere in the
package.
"""
from __future__ import annotations

import numpy as np
import openmm.unit as unit

_NM_PS = unit.nanometer / unit.picosecond
KJ = unit.kilojoule_per_mole


def read_state(context, energy=True):
    """(x, v, E) from one getState call; E is kinetic + potential (kJ/mol), or None."""
    st = context.getState(getPositions=True, getVelocities=True, getEnergy=energy)
    x = np.array(st.getPositions(asNumpy=True).value_in_unit(unit.nanometer))
    v = np.array(st.getVelocities(asNumpy=True).value_in_unit(_NM_PS))
    e = (st.getKineticEnergy() + st.getPotentialEnergy()).value_in_unit(KJ) if energy else None
    return x, v, e


def rms_deviation(x, y) -> float:
    """Root-mean-square distance between two (N, 3) position sets (nm)."""
    return float(np.sqrt(np.mean(np.sum((np.asarray(x) - np.asarray(y)) ** 2, axis=1))))


def finite(*arrays) -> bool:
    return all(np.all(np.isfinite(a)) for a in arrays if a is not None)
