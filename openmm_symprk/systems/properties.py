"""Facts about an ``openmm.System`` that every layer needs, each computed in one place: masses, constraints,
degrees of freedom, virtual sites and frozen particles, molecules, and the signature an integrator records
of the System it was compiled for.  Units: nm, Da."""
from __future__ import annotations

import hashlib
from dataclasses import dataclass

import numpy as np
import openmm as mm
import openmm.app as app
import openmm.unit as unit

from ..physics.velocity_rescaling import thermostat_dof

__all__ = ["masses", "has_constraints", "constraint_arrays", "constraint_violation", "degrees_of_freedom",
           "thermostat_degrees_of_freedom", "virtual_sites", "frozen_particles", "force_names", "molecules", "SystemSignature", "signature"]


def masses(system: mm.System) -> np.ndarray:
    """Particle masses (Da) from the System, float64."""
    return np.array([system.getParticleMass(i).value_in_unit(unit.dalton) for i in range(system.getNumParticles())],
                    dtype=np.float64)


def has_constraints(system: mm.System) -> bool:
    return system.getNumConstraints() > 0


def constraint_arrays(system: mm.System):
    """(i, j, d): the constrained pairs and their distances (nm) as arrays."""
    n = system.getNumConstraints()
    i, j, d = np.empty(n, dtype=int), np.empty(n, dtype=int), np.empty(n)
    for k in range(n):
        a, b, dk = system.getConstraintParameters(k)
        i[k], j[k] = a, b
        d[k] = dk.value_in_unit(unit.nanometer) if unit.is_quantity(dk) else dk
    return i, j, d


def constraint_violation(x, constraints) -> float:
    """Largest relative violation max_k |r_k - d_k| / d_k of the constraints (a System or the arrays of
    :func:`constraint_arrays`) at positions ``x`` (nm); 0 without constraints."""
    i, j, d = constraint_arrays(constraints) if isinstance(constraints, mm.System) else constraints
    if len(d) == 0:
        return 0.0
    x = np.asarray(x, dtype=np.float64)
    r = np.linalg.norm(x[i] - x[j], axis=1)
    return float(np.max(np.abs(r - d) / d))


def degrees_of_freedom(system: mm.System) -> int:
    """3 x (particles with mass) - constraints - 3 if the System has a CMMotionRemover (OpenMM's count, as in
    StateDataReporter)."""
    m = masses(system)
    dof = 3 * int(np.count_nonzero(m > 0)) - system.getNumConstraints()
    if any(isinstance(f, mm.CMMotionRemover) for f in system.getForces()):
        dof -= 3
    return dof


def thermostat_degrees_of_freedom(system: mm.System, isolated: bool) -> int:
    """Degrees of freedom a velocity-rescaling thermostat samples in ``system``: 3 per particle with mass
    (virtual sites and other massless particles never move by themselves), minus one per constraint that
    involves a particle with mass (OpenMM's rule, as in StateDataReporter), minus 3 for the centre-of-mass
    velocity (kept), minus 3 more for the rigid rotation when the System is ``isolated`` (kept too).
    The rule itself is :func:`openmm_symprk.physics.velocity_rescaling.thermostat_dof`."""
    m = masses(system)
    n_constraints = 0
    for k in range(system.getNumConstraints()):
        i, j, _ = system.getConstraintParameters(k)
        n_constraints += bool(m[i] > 0 or m[j] > 0)
    return thermostat_dof(int(np.count_nonzero(m > 0)), n_constraints, isolated)


def virtual_sites(system: mm.System) -> list:
    return [i for i in range(system.getNumParticles()) if system.isVirtualSite(i)]


def frozen_particles(system: mm.System) -> list:
    """Massless particles that are not virtual sites: OpenMM never moves them, and their forces on the rest
    act like an external field (no conservation of momentum about them)."""
    return [i for i in range(system.getNumParticles())
            if system.getParticleMass(i).value_in_unit(unit.dalton) == 0 and not system.isVirtualSite(i)]


def force_names(system: mm.System) -> list:
    return [type(system.getForce(i)).__name__ for i in range(system.getNumForces())]


# -- molecules ------------------------------------------------------------------------------------
def _components(n, pairs):
    parent = list(range(n))

    def find(i):
        while parent[i] != i:
            parent[i] = parent[parent[i]]
            i = parent[i]
        return i

    for a, b in pairs:
        ra, rb = find(int(a)), find(int(b))
        if ra != rb:
            parent[max(ra, rb)] = min(ra, rb)
    groups: dict = {}
    for i in range(n):
        groups.setdefault(find(i), []).append(i)
    return [np.array(g, dtype=int) for g in sorted(groups.values(), key=lambda g: g[0])]


def _system_pairs(system: mm.System):
    for k in range(system.getNumConstraints()):
        i, j, _ = system.getConstraintParameters(k)
        yield i, j
    for f in system.getForces():
        if isinstance(f, (mm.HarmonicBondForce, mm.CustomBondForce)):
            for k in range(f.getNumBonds()):
                p = f.getBondParameters(k)
                yield p[0], p[1]
        elif isinstance(f, (mm.HarmonicAngleForce, mm.CustomAngleForce)):
            for k in range(f.getNumAngles()):
                p = f.getAngleParameters(k)
                yield p[0], p[1]
                yield p[1], p[2]
    for i in range(system.getNumParticles()):
        if system.isVirtualSite(i):
            vs = system.getVirtualSite(i)
            for k in range(vs.getNumParticles()):
                yield i, vs.getParticle(k)


def molecules(source) -> list:
    """Molecules as arrays of particle indices (connected components).

    ``source``: a Context or Simulation (``Context.getMolecules()``: every bonded force and constraint), a
    Topology (its bonds), or a System (constraints, bond and angle forces, virtual sites)."""
    if isinstance(source, app.Simulation):
        source = source.context
    if isinstance(source, mm.Context):
        return [np.array(sorted(g), dtype=int) for g in source.getMolecules()]
    if isinstance(source, app.Topology):
        return _components(source.getNumAtoms(), ((b[0].index, b[1].index) for b in source.bonds()))
    if isinstance(source, mm.System):
        return _components(source.getNumParticles(), _system_pairs(source))
    raise TypeError(f"molecules() takes a Context, Simulation, Topology or System, got {type(source).__name__}")


# -- what an integrator records of its System -------------------------------------------------------
@dataclass(frozen=True)
class SystemSignature:
    """What an integrator was compiled for: enough to refuse a Context of another System."""

    n_particles: int
    constraints: bool
    virtual_sites: bool
    total_mass: float  # Da
    masses_digest: str  # sha1 of the float64 masses

    def mismatch(self, other: "SystemSignature") -> list:
        """Human-readable differences from ``other`` (empty if they match)."""
        out = []
        if self.n_particles != other.n_particles:
            out.append(f"{other.n_particles} particles instead of {self.n_particles}")
        if self.constraints != other.constraints:
            out.append("constraints" if other.constraints else "no constraints")
        if self.virtual_sites != other.virtual_sites:
            out.append("virtual sites" if other.virtual_sites else "no virtual sites")
        if self.n_particles == other.n_particles and self.masses_digest != other.masses_digest:
            out.append("other masses")
        return out


def signature(system: mm.System) -> SystemSignature:
    m = masses(system)
    return SystemSignature(system.getNumParticles(), has_constraints(system), bool(virtual_sites(system)),
                           float(m.sum()), hashlib.sha1(m.tobytes()).hexdigest())
