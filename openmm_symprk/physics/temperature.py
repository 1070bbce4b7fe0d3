"""Translational and rotational kinetic energy and temperature of molecules (pure numpy).

The kinetic energy of a molecule splits into the motion of its centre of mass, its rigid rotation about it and
what is left (internal motion, zero for a rigid molecule whose velocities satisfy its constraints):

    K_trans = 1/2 M |V|^2,    K_rot = 1/2 L^T I^-1 L,    K_int = K - K_trans - K_rot

with V the centre-of-mass velocity, L the angular momentum about the centre of mass and I the inertia tensor
there.  Equipartition gives each degree of freedom kT/2 on average, so

    T_trans = 2 K_trans / (k (3 N_mol - c)),    T_rot = 2 K_rot / (k f_rot)

where c = 3 when the total momentum P is fixed (an isolated or NVE system without external forces conserves
it, removing three translational degrees of freedom; 0 otherwise); then the kinetic energy of the motion of
the whole set, |P|^2 / 2 M_total, is not thermal and is taken out of K_trans first (it is zero when P is, and
a state drawn from a thermostat without a CMMotionRemover carries ~3/2 kT of it, which would otherwise warm
T_trans by ~kT/(N_mol k): 1.4 K for 216 waters) and f_rot counts 3 per non-linear molecule,
2 per linear one and 0 per atom.  Units: nm, ps, Da, kJ/mol, K.
"""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from .momenta import linear_momentum, molecule_frames

#: Gas constant in kJ/mol/K.
R_KJ = 0.00831446261815324

__all__ = ["MoleculeKinetics", "molecule_kinetics", "KineticTemperatures", "kinetic_temperatures", "R_KJ"]


@dataclass
class MoleculeKinetics:
    """Per molecule: translational, rotational and total kinetic energy (kJ/mol) and rotational degrees of
    freedom (3, 2 or 0)."""

    translational: np.ndarray
    rotational: np.ndarray
    total: np.ndarray
    rotational_dof: np.ndarray


def _groups_by_size(molecules):
    by_size: dict = {}
    for k, g in enumerate(molecules):
        by_size.setdefault(len(g), []).append(k)
    return {s: (np.array(ks), np.array([molecules[k] for k in ks], dtype=int)) for s, ks in by_size.items()}


def molecule_kinetics(x, v, m, molecules, linear_tol: float = 1e-8) -> MoleculeKinetics:
    """Kinetic energy of every molecule (lists of particle indices) split into translation and rotation.
    Massless particles (virtual sites) carry nothing; a molecule whose smallest principal moment is below
    ``linear_tol`` times its largest is linear (two rotational degrees of freedom)."""
    x, v, m = (np.asarray(a, dtype=np.float64) for a in (x, v, m))
    n = len(molecules)
    trans, rot, total, dof = np.zeros(n), np.zeros(n), np.zeros(n), np.zeros(n, dtype=int)
    for size, (ks, idx) in _groups_by_size(molecules).items():
        fr = molecule_frames(x, v, m, idx)
        mg, vg = m[idx], v[idx]
        ok = fr.M > 0
        total[ks] = 0.5 * (mg[..., None] * vg * vg).sum(axis=(1, 2))
        trans[ks] = np.where(ok, 0.5 * fr.M * (fr.V * fr.V).sum(axis=1), 0.0)
        if size == 1:
            continue
        moments = np.linalg.eigvalsh(fr.inertia)  # ascending
        linear = moments[:, 0] <= linear_tol * np.maximum(moments[:, 2], 1e-300)
        omega = np.einsum("nij,nj->ni", np.linalg.pinv(fr.inertia, rcond=linear_tol, hermitian=True), fr.L)
        rot[ks] = np.where(ok, 0.5 * (fr.L * omega).sum(axis=1), 0.0)
        dof[ks] = np.where(ok & (moments[:, 2] > 0), np.where(linear, 2, 3), 0)
    return MoleculeKinetics(trans, rot, total, dof)


@dataclass
class KineticTemperatures:
    """Kinetic temperatures (K) of a set of molecules, with the degrees of freedom they were divided by."""

    translational: float
    rotational: float
    internal: float  # nan without internal degrees of freedom (every molecule rigid)
    translational_dof: int
    rotational_dof: int
    internal_dof: int

    @property
    def difference(self) -> float:
        """T_rot - T_trans: zero on average at equilibrium (equipartition)."""
        return self.rotational - self.translational


def kinetic_temperatures(x, v, m, molecules, momentum_fixed: bool = True, constraints: int | None = None,
                         linear_tol: float = 1e-8) -> KineticTemperatures:
    """Translational, rotational and internal kinetic temperature of ``molecules``.

    ``momentum_fixed``: the total momentum is conserved (or removed), so translation has 3 N_mol - 3 degrees
    of freedom and the kinetic energy of the centre of mass of all the molecules is not counted in it (the
    temperatures are then the same in any frame moving uniformly); ``constraints``: the number of distance constraints inside the molecules (for the internal
    degrees of freedom: 3 n - 6 per rigid non-linear molecule is all of them)."""
    mk = molecule_kinetics(x, v, m, molecules, linear_tol)
    m = np.asarray(m, dtype=np.float64)
    k_trans = float(mk.translational.sum())
    if momentum_fixed:  # the motion of the whole set is not thermal: out of K_trans (zero when P = 0)
        idx = np.concatenate([np.asarray(g, dtype=int) for g in molecules]) if len(molecules) else np.zeros(0, int)
        p = linear_momentum(np.asarray(v)[idx], m[idx])
        k_trans -= float(p @ p) / (2.0 * float(m[idx].sum())) if m[idx].sum() > 0 else 0.0
    n_massive = sum(int(np.count_nonzero(m[np.asarray(g)] > 0)) for g in molecules)
    n_mol = sum(1 for g in molecules if m[np.asarray(g)].sum() > 0)
    f_trans = 3 * n_mol - (3 if momentum_fixed else 0)
    f_rot = int(mk.rotational_dof.sum())
    f_int = 3 * n_massive - 3 * n_mol - f_rot - int(constraints or 0)
    k_int = float(mk.total.sum() - mk.translational.sum() - mk.rotational.sum())
    return KineticTemperatures(
        translational=2 * k_trans / (R_KJ * f_trans) if f_trans > 0 else float("nan"),
        rotational=2 * float(mk.rotational.sum()) / (R_KJ * f_rot) if f_rot > 0 else float("nan"),
        internal=2 * k_int / (R_KJ * f_int) if f_int > 0 else float("nan"),
        translational_dof=f_trans, rotational_dof=f_rot, internal_dof=max(f_int, 0))
