"""Observables of one sample of a run, in float64 from the arrays OpenMM returns.

Units: nm, ps, Da, kJ/mol; momentum in Da nm/ps, angular momentum (about the origin) in Da nm^2/ps.
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


def momentum(v, m) -> np.ndarray:
    return (m[:, None] * v).sum(0)


def angular_momentum(x, v, m) -> np.ndarray:
    return (m[:, None] * np.cross(x, v)).sum(0)


def constraint_error(x, cons) -> float:
    """Largest relative bond-length error max |r_ij - d| / d over the constraints (0 without any)."""
    i, j, d = cons
    if len(d) == 0:
        return 0.0
    r = np.linalg.norm(x[i] - x[j], axis=1)
    return float(np.max(np.abs(r - d) / d))


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
