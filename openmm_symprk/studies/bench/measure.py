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


def drift_with_error(t, y) -> tuple:
    """(slope, standard error) of a least-squares line through (t, y), the error inflated by the statistical
    inefficiency of the residuals (1 + 2 * their summed autocorrelation up to its first negative value), since the
    energy of an MD run is correlated from sample to sample."""
    t = np.asarray(t, float)
    y = np.asarray(y, float)
    n = len(t)
    if n < 4 or np.ptp(t) == 0:
        return 0.0, float("nan")
    slope, intercept = np.polyfit(t, y, 1)
    r = y - (slope * t + intercept)
    var = float(np.sum(r * r) / (n - 2))
    g = 1.0
    if var > 0:
        c = np.correlate(r - r.mean(), r - r.mean(), "full")[n - 1:] / (np.arange(n, 0, -1) * r.var())
        for rho in c[1:n // 2]:
            if rho <= 0:
                break
            g += 2 * rho
    se = np.sqrt(var * g / float(np.sum((t - t.mean()) ** 2)))
    return float(slope), float(se)
