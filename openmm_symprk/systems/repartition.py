"""Hydrogen mass repartitioning (HMR) of a System, rigid water included, and an equilibrium state carried over.

OpenMM's ``ForceField.createSystem(hydrogenMass=...)`` leaves the hydrogens of rigid water alone, so a box of
rigid water is the same System with and without it.  :func:`repartition_hydrogen_mass` moves mass onto every
hydrogen bonded to a heavy atom (water's too), keeping each molecule's total mass.

Masses do not enter the equilibrium distribution of positions, so an equilibrated state stays one under new
masses once the velocities are redrawn for them.  :func:`rigid_velocities_for_masses` does it without new random
numbers for rigid molecules: each molecule keeps its centre-of-mass velocity (its mass is unchanged) and its
angular velocity w becomes I_new^-1/2 I_old^1/2 w (I: the inertia tensor about the molecule's centre of mass),
which keeps each molecule's rotational kinetic energy exactly and maps the Maxwell-Boltzmann distribution of w
(covariance kT I_old^-1) onto the one for the new masses (kT I_new^-1).  Units: nm, ps, Da.
"""
from __future__ import annotations

import numpy as np
import openmm as mm
import openmm.app as app
import openmm.unit as unit

from ..physics.momenta import molecule_frames
from .properties import masses
from ..support.errors import InputError

__all__ = ["repartition_hydrogen_mass", "rigid_velocities_for_masses"]


def repartition_hydrogen_mass(system: mm.System, topology: app.Topology, hydrogen_mass: float) -> mm.System:
    """A copy of ``system`` with every hydrogen bonded (in ``topology``) to a heavy atom at ``hydrogen_mass`` Da,
    the difference taken from that heavy atom.  ValueError when a heavy atom would be left with less than 1 Da."""
    if isinstance(hydrogen_mass, bool) or not 1.0 <= float(hydrogen_mass) <= 5.0:
        raise InputError(f"hydrogen_mass must be between 1 and 5 Da (HMR uses 1.5-4), got {hydrogen_mass!r}")
    out = mm.XmlSerializer.deserialize(mm.XmlSerializer.serialize(system))
    m = masses(system).copy()
    H = app.element.hydrogen
    for a, b in topology.bonds():
        if (a.element is H) == (b.element is H):
            continue
        h, heavy = (a, b) if a.element is H else (b, a)
        if m[h.index] <= 0:
            continue  # a virtual site named as hydrogen
        delta = float(hydrogen_mass) - m[h.index]
        m[h.index] += delta
        m[heavy.index] -= delta
        if m[heavy.index] < 1.0:
            raise InputError(f"hydrogen mass {hydrogen_mass} Da leaves atom {heavy.index} ({heavy.name}) with "
                             f"{m[heavy.index]:.2f} Da: use a smaller hydrogen mass")
    for i, mi in enumerate(m):
        out.setParticleMass(i, mi * unit.dalton)
    return out


def rigid_velocities_for_masses(x, v, m_old, m_new, molecules) -> np.ndarray:
    """Velocities (N, 3) nm/ps for the masses ``m_new`` from rigid molecules' velocities ``v`` under ``m_old``
    (positions ``x``; ``molecules``: lists of atom indices, one length): each molecule keeps its total mass's
    velocity and its rotational kinetic energy (module docstring).  Molecules' internal motion is assumed zero
    (rigid: velocities satisfying the constraints)."""
    x, v = np.asarray(x, dtype=np.float64), np.asarray(v, dtype=np.float64)
    m_old, m_new = np.asarray(m_old, dtype=np.float64), np.asarray(m_new, dtype=np.float64)
    idx = np.asarray(molecules, dtype=int)
    old, new = molecule_frames(x, v, m_old, idx), molecule_frames(x, v, m_new, idx)
    if not np.allclose(old.M, new.M, rtol=1e-12, atol=0):
        raise InputError("the new masses change a molecule's total mass: repartition within each molecule")
    w_old = np.linalg.solve(old.inertia, old.L[..., None])[..., 0]
    w_new = np.einsum("nij,njk,nk->ni", _sym_power(new.inertia, -0.5), _sym_power(old.inertia, 0.5), w_old)
    out = v.copy()
    out[idx] = old.V[:, None, :] + np.cross(w_new[:, None, :], new.r)
    return out


def _sym_power(a, p):
    """a^p for symmetric positive definite matrices a (n, 3, 3)."""
    vals, vecs = np.linalg.eigh(a)
    return np.einsum("nij,nj,nkj->nik", vecs, vals ** p, vecs)
