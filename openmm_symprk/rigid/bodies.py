"""Molecules moved as rigid bodies with a Lie-Poisson (NO_SQUISH-type) splitting, forces from OpenMM.

What a rigid-body engine does with rigid water, for comparison with the constrained (RATTLE/SETTLE)
formulation that :class:`~openmm_symprk.SymplecticIntegrator` runs inside OpenMM.  Each molecule carries
its centre of mass X, momentum P, orientation Q (body -> space rotation, atoms at X + Q b) and body angular
momentum pi.  A step is a catalogue kick/drift splitting (``verlet`` gives NO_SQUISH of Miller et al.,
J. Chem. Phys. 116, 8649 (2002)) where

* kick(c h):   P += c h F,  pi += c h Q^T tau   (F, tau: total force and torque on the molecule),
* drift(c h):  X += c h P/M, and the free rotor for c h by the X1(1/2) X2(1/2) X3(1) X2(1/2) X1(1/2)
  sequence of :mod:`openmm_symprk.rigid.lie_poisson` (``splitting-2``): each X_k is an exact rotation
  about body axis k, so |pi| (the Casimir) and the rigidity are exact.

OpenMM's CustomIntegrator has no per-molecule reductions (sums of forces or torques over a group of
atoms) and the native plugin implements a constrained engine, not a rigid-body one, so this engine runs in
numpy and asks an OpenMM Context only for forces: each force evaluation is a ``setPositions`` plus a
``getState(getForces=True)``.  Per force evaluation it reproduces what a rigid-body engine computes; its wall
time is not a fair speed comparison (the transfers cost about as much as the forces for a small box).

Units: nm, ps, Da, kJ/mol.
"""
from __future__ import annotations

import numpy as np
import openmm as mm
import openmm.unit as unit

from ..methods.catalogue import methods as catalogue_methods
from ..methods.resolved import resolve
from ..methods.splitting import DRIFT, KICK, Splitting
from ..physics.momenta import molecule_frames
from .lie_poisson import splitting_of
from ..support.errors import InputError

__all__ = ["RigidBodies", "rigid_body_state"]


def rigid_body_state(x, v, m, molecules):
    """(X, V, Q, body, moments, pi) of molecules (an (n, k) index array, all the same size and massive):
    centre of mass and its velocity, principal axes as orientation (det +1), atom coordinates in the body
    frame, principal moments and body angular momentum."""
    fr = molecule_frames(x, v, m, molecules)
    moments, Q = np.linalg.eigh(fr.inertia)
    if np.any(moments[:, 0] <= 1e-8 * moments[:, 2]):
        raise InputError("a molecule is linear (a zero principal moment): this engine needs 3 rotational "
                         "degrees of freedom per molecule")
    Q[np.linalg.det(Q) < 0, :, 2] *= -1.0
    body = np.einsum("nji,nkj->nki", Q, fr.r)  # b = Q^T r
    pi = np.einsum("nji,nj->ni", Q, fr.L)
    return fr.com, fr.V, Q, body, moments, pi


class RigidBodies:
    """Rigid molecules of an OpenMM ``system`` integrated as rigid bodies (see the module docstring).

    ``molecules``: the rigid groups (same number of atoms each, every atom massive; rigid water);
    ``method``: a catalogue kick/drift splitting (``verlet`` = NO_SQUISH, ``omelyan-2``, ...);
    ``platform``/``properties``: where OpenMM computes the forces.  The System's constraints are not used
    (rigidity is exact); its forces must not depend on velocities."""

    def __init__(self, system: mm.System, positions, velocities, molecules, step_ps: float, method: str = "verlet",
                 platform="CPU", properties=None):
        if not step_ps > 0:
            raise InputError(f"step_ps must be positive, got {step_ps!r}")
        resolved = resolve(method)  # rigidity is exact: no constraint steps
        if not resolved.is_splitting or set(resolved.splitting.labels) - {KICK, DRIFT}:
            raise InputError(f"method {method!r} is not a kick/drift splitting; use one of "
                             f"{', '.join(m.name for m in catalogue_methods.by_family('splitting'))}")
        self.method, self.h = resolved.name, float(step_ps)
        self.splitting: Splitting = resolved.splitting
        self.rotor = [(int(label[1]) - 1, float(c)) for label, c in splitting_of("splitting-2").coefficients()]
        self.m = np.array([system.getParticleMass(i).value_in_unit(unit.dalton) for i in range(system.getNumParticles())])
        self.idx = np.asarray(molecules, dtype=int)
        if self.idx.ndim != 2 or np.any(self.m[self.idx] <= 0):
            raise InputError("molecules must all have the same number of atoms, all with mass")
        covered = np.zeros(len(self.m), dtype=bool)
        covered[self.idx.ravel()] = True
        if not covered.all():
            raise InputError(f"{int((~covered).sum())} particles are in no molecule: every particle must be in one")
        x = np.asarray(positions, dtype=np.float64)
        v = np.asarray(velocities, dtype=np.float64)
        self.X, V, self.Q, self.body, self.moments, self.pi = rigid_body_state(x, v, self.m, self.idx)
        self.mg = self.m[self.idx]
        self.M = self.mg.sum(axis=1)
        self.P = self.M[:, None] * V
        plat = mm.Platform.getPlatformByName(platform) if isinstance(platform, str) else platform
        self._integrator = mm.VerletIntegrator(self.h)
        self.context = mm.Context(system, self._integrator, plat, properties or {})
        self._forces = None
        self.force_evaluations = 0
        self.steps = 0

    # -- state ------------------------------------------------------------------------------------
    def positions(self) -> np.ndarray:
        x = np.empty((len(self.m), 3))
        x[self.idx] = self.X[:, None, :] + np.einsum("nij,nkj->nki", self.Q, self.body)
        return x

    def velocities(self) -> np.ndarray:
        omega_space = np.einsum("nij,nj->ni", self.Q, self.pi / self.moments)
        r = np.einsum("nij,nkj->nki", self.Q, self.body)
        v = np.empty((len(self.m), 3))
        v[self.idx] = (self.P / self.M[:, None])[:, None, :] + np.cross(omega_space[:, None, :], r)
        return v

    def kinetic_energy(self) -> float:
        return float(0.5 * ((self.P ** 2).sum(axis=1) / self.M).sum() + 0.5 * (self.pi ** 2 / self.moments).sum())

    def potential_energy(self) -> float:
        self.context.setPositions(self.positions())
        st = self.context.getState(getEnergy=True)
        return st.getPotentialEnergy().value_in_unit(unit.kilojoule_per_mole)

    # -- sub-flows ----------------------------------------------------------------------------------
    def _force(self):
        if self._forces is None:
            self.context.setPositions(self.positions())
            f = self.context.getState(getForces=True).getForces(asNumpy=True)
            self._forces = np.asarray(f.value_in_unit(unit.kilojoule_per_mole / unit.nanometer))[self.idx]
            self.force_evaluations += 1
        return self._forces

    def _kick(self, dt):
        f = self._force()
        r = np.einsum("nij,nkj->nki", self.Q, self.body)
        self.P += dt * f.sum(axis=1)
        torque = np.cross(r, f).sum(axis=1)
        self.pi += dt * np.einsum("nji,nj->ni", self.Q, torque)

    def _drift(self, dt):
        self.X += dt * self.P / self.M[:, None]
        pi, Q = self.pi, self.Q
        for axis, c in self.rotor:
            j, k = (axis + 1) % 3, (axis + 2) % 3
            angle = c * dt * pi[:, axis] / self.moments[:, axis]
            cs, sn = np.cos(angle), np.sin(angle)
            # pi <- R_axis(angle)^T pi ; Q <- Q R_axis(angle)
            pj, pk = pi[:, j].copy(), pi[:, k].copy()
            pi[:, j] = cs * pj + sn * pk
            pi[:, k] = -sn * pj + cs * pk
            qj, qk = Q[:, :, j].copy(), Q[:, :, k].copy()
            Q[:, :, j] = cs[:, None] * qj + sn[:, None] * qk
            Q[:, :, k] = -sn[:, None] * qj + cs[:, None] * qk
        self._forces = None

    def step(self, n: int = 1):
        """Advance ``n`` steps."""
        seq = self.splitting.coefficients()
        for _ in range(int(n)):
            for label, c in seq:
                (self._kick if label == KICK else self._drift)(float(c) * self.h)
            self.steps += 1
