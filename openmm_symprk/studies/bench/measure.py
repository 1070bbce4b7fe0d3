"""Observables of one sample of a run, in float64 from the arrays OpenMM returns.

Units: nm, ps, Da, kJ/mol.  Momenta come from :mod:`openmm_symprk.physics` and constraint errors from
:mod:`openmm_symprk.systems.properties`, as everywhere in the package.
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


def drift_rate(t, de) -> float:
    """Slope of a least-squares line through (t, dE): the energy drift (per ps)."""
    t = np.asarray(t, float)
    de = np.asarray(de, float)
    if len(t) < 2 or np.ptp(t) == 0:
        return 0.0
    return float(np.polyfit(t, de, 1)[0])


def finite(*arrays) -> bool:
    return all(np.all(np.isfinite(a)) for a in arrays if a is not None)
