"""Float64 conservation diagnostics from an OpenMM Context (or a State plus its System).

Everything here is computed in float64 from the positions and velocities OpenMM returns, with the
masses taken from the System (element masses in a Topology differ from force-field masses by up to
0.003 amu).  Units: nm, ps, amu (dalton), kJ/mol; momentum in amu nm/ps, angular momentum in
amu nm^2/ps.  Massless particles (virtual sites) carry no momentum and are ignored.

    from openmm_symprk import linear_momentum, angular_momentum
    P = linear_momentum(context)                   # (3,)
    L = angular_momentum(context)                  # about the centre of mass
    L0 = angular_momentum(context, about="origin")
    d = diagnostics(context)                       # everything from one getState call

The figures are as precise as the state they are computed from: in-process values are float64 (on
the single-precision OpenCL/CUDA modes the state itself is stored in float32); a trajectory stored in
float32 (DCD, TRR, XTC) limits them to ~1e-7 relative (see :mod:`openmm_symprk.analysis`).
"""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np
import openmm as mm
import openmm.app as app
import openmm.unit as unit

_NM = unit.nanometer
_NM_PS = unit.nanometer / unit.picosecond
_KJ = unit.kilojoule_per_mole

__all__ = ["masses_of", "linear_momentum", "angular_momentum", "molecules", "molecule_angular_momentum",
           "kinetic_energy", "energies", "constraint_violation", "degrees_of_freedom", "centre_of_mass",
           "inertia_tensor", "Diagnostics", "diagnostics"]


# -- inputs ---------------------------------------------------------------------------------------
def masses_of(system: mm.System) -> np.ndarray:
    """Particle masses (amu) from the System, float64."""
    return np.array([system.getParticleMass(i).value_in_unit(unit.dalton)
                     for i in range(system.getNumParticles())], dtype=np.float64)


def _array(q, u) -> np.ndarray:
    if unit.is_quantity(q):
        q = q.value_in_unit(u)
    return np.asarray(q, dtype=np.float64).reshape(-1, 3)


def _resolve(obj, system=None, masses=None, positions=True, velocities=True, energy=False):
    """(x, v, m, state, system) from a Context, a State (+ System) or arrays.

    ``obj`` may be an ``openmm.Context``, an ``app.Simulation``, an ``openmm.State`` (then ``system``
    or ``masses`` is needed) or a tuple ``(positions, velocities)`` of arrays (nm, nm/ps)."""
    state = None
    if isinstance(obj, app.Simulation):
        obj = obj.context
    if isinstance(obj, mm.Context):
        system = system if system is not None else obj.getSystem()
        state = obj.getState(getPositions=positions, getVelocities=velocities, getEnergy=energy)
    elif isinstance(obj, mm.State):
        state = obj
    elif isinstance(obj, tuple) and len(obj) == 2:
        x, v = (None if a is None else _array(a, u) for a, u in zip(obj, (_NM, _NM_PS)))
        if masses is None:
            if system is None:
                raise TypeError("positions/velocities arrays need masses= or system=")
            masses = masses_of(system)
        return x, v, np.asarray(masses, dtype=np.float64), None, system
    else:
        raise TypeError(f"expected an openmm.Context, Simulation, State or (positions, velocities), "
                        f"got {type(obj).__name__}")
    if masses is None:
        if system is None:
            raise TypeError("a State carries no masses: pass system= (or masses=)")
        masses = masses_of(system)
    x = state.getPositions(asNumpy=True).value_in_unit(_NM) if positions else None
    v = state.getVelocities(asNumpy=True).value_in_unit(_NM_PS) if velocities else None
    x = None if x is None else np.asarray(x, dtype=np.float64)
    v = None if v is None else np.asarray(v, dtype=np.float64)
    return x, v, np.asarray(masses, dtype=np.float64), state, system


# -- momentum maps ----------------------------------------------------------------------------
def centre_of_mass(x: np.ndarray, m: np.ndarray) -> np.ndarray:
    M = m.sum()
    if M <= 0:
        raise ValueError("the system has no mass (all particles are massless)")
    return (m[:, None] * x).sum(axis=0) / M


def inertia_tensor(x: np.ndarray, m: np.ndarray, about=None) -> np.ndarray:
    """Inertia tensor (amu nm^2) about ``about`` (default the centre of mass)."""
    c = centre_of_mass(x, m) if about is None else np.asarray(about, dtype=np.float64)
    r = x - c
    r2 = (r * r).sum(axis=1)
    return np.eye(3) * (m * r2).sum() - np.einsum("i,ij,ik->jk", m, r, r)


def _linear(v, m):
    return (m[:, None] * v).sum(axis=0)


def _angular(x, v, m, about):
    if isinstance(about, str):
        if about in ("com", "centre", "center", "cm"):
            c = centre_of_mass(x, m)
        elif about == "origin":
            c = np.zeros(3)
        else:
            raise ValueError(f"about must be 'com', 'origin' or a point (nm), got {about!r}")
    else:
        c = np.asarray(about, dtype=np.float64).reshape(3)
    return (m[:, None] * np.cross(x - c, v)).sum(axis=0)


def linear_momentum(obj, system: mm.System | None = None, masses=None) -> np.ndarray:
    """Total linear momentum sum_i m_i v_i (amu nm/ps), float64, shape (3,)."""
    _, v, m, _, _ = _resolve(obj, system, masses, positions=False)
    return _linear(v, m)


def angular_momentum(obj, system: mm.System | None = None, about="com", masses=None) -> np.ndarray:
    """Total angular momentum sum_i m_i (x_i - c) x v_i (amu nm^2/ps), float64, shape (3,).

    ``about``: "com" (the centre of mass, default), "origin", or a point in nm.  In an isolated
    system both L about the centre of mass and L about the origin are conserved (L_origin = L_com +
    M r_cm x V_cm, with V_cm constant); a CMMotionRemover keeps the first and changes the second."""
    x, v, m, _, _ = _resolve(obj, system, masses)
    return _angular(x, v, m, about)


# -- molecules ----------------------------------------------------------------------------------
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
    """Molecules as lists of particle indices (connected components).

    ``source``: a Context (uses ``Context.getMolecules()``, i.e. every bonded force and constraint),
    a Topology (its bonds), or a System (constraints, bond and angle forces, virtual sites)."""
    if isinstance(source, app.Simulation):
        source = source.context
    if isinstance(source, mm.Context):
        return [np.array(sorted(g), dtype=int) for g in source.getMolecules()]
    if isinstance(source, app.Topology):
        return _components(source.getNumAtoms(), ((b[0].index, b[1].index) for b in source.bonds()))
    if isinstance(source, mm.System):
        return _components(source.getNumParticles(), _system_pairs(source))
    raise TypeError(f"molecules() takes a Context, Topology or System, got {type(source).__name__}")


def molecule_angular_momentum(obj, system: mm.System | None = None, groups=None, masses=None) -> np.ndarray:
    """Angular momentum of each molecule about its own centre of mass, shape (n_molecules, 3).

    ``groups``: lists of particle indices (default: :func:`molecules` of the Context or System).
    Massless molecules give zeros.  This is not a conserved quantity (molecules exchange angular
    momentum through intermolecular forces); their sum plus the orbital part is."""
    x, v, m, _, system = _resolve(obj, system, masses)
    if groups is None:
        src = obj.context if isinstance(obj, app.Simulation) else obj
        groups = molecules(src if isinstance(src, mm.Context) else system)
    out = np.zeros((len(groups), 3))
    for k, g in enumerate(groups):
        g = np.asarray(g, dtype=int)
        mg = m[g]
        if mg.sum() > 0:
            out[k] = _angular(x[g], v[g], mg, "com")
    return out


# -- energies and constraints --------------------------------------------------------------------
def kinetic_energy(obj, system: mm.System | None = None, masses=None) -> float:
    """1/2 sum m v^2 (kJ/mol) in float64 from the current velocities (on-step velocities for
    CustomIntegrators; VerletIntegrator's leapfrog state holds half-step velocities)."""
    _, v, m, _, _ = _resolve(obj, system, masses, positions=False)
    return float(0.5 * (m[:, None] * v * v).sum())


def energies(obj, system: mm.System | None = None, masses=None) -> dict:
    """{'kinetic', 'potential', 'total'} in kJ/mol: kinetic in float64 from the velocities, potential
    from OpenMM (needs a Context or a State made with getEnergy=True)."""
    if isinstance(obj, app.Simulation):
        obj = obj.context
    if isinstance(obj, mm.Context):
        system = system if system is not None else obj.getSystem()
        obj = obj.getState(getVelocities=True, getEnergy=True)
    _, v, m, state, _ = _resolve(obj, system, masses, positions=False)
    ke = float(0.5 * (m[:, None] * v * v).sum())
    pe = state.getPotentialEnergy().value_in_unit(_KJ)
    return {"kinetic": ke, "potential": pe, "total": ke + pe}


def constraint_violation(obj, system: mm.System | None = None) -> float:
    """Largest relative constraint violation max_k |r_k - d_k| / d_k (0 without constraints)."""
    x, _, _, _, system = _resolve(obj, system, np.zeros(0), velocities=False)
    if system is None:
        raise TypeError("a State carries no constraints: pass system=")
    return _constraint_violation(x, system)


def _constraint_violation(x, system):
    n = system.getNumConstraints()
    if n == 0:
        return 0.0
    ij = np.empty((n, 2), dtype=int)
    d = np.empty(n)
    for k in range(n):
        i, j, dk = system.getConstraintParameters(k)
        ij[k] = i, j
        d[k] = dk.value_in_unit(_NM) if unit.is_quantity(dk) else dk
    r = np.linalg.norm(x[ij[:, 0]] - x[ij[:, 1]], axis=1)
    return float(np.max(np.abs(r - d) / d))


def degrees_of_freedom(system: mm.System) -> int:
    """3 x (particles with mass) - constraints - 3 if the System has a CMMotionRemover."""
    n = sum(1 for i in range(system.getNumParticles()) if system.getParticleMass(i).value_in_unit(unit.dalton) > 0)
    dof = 3 * n - system.getNumConstraints()
    if any(isinstance(f, mm.CMMotionRemover) for f in system.getForces()):
        dof -= 3
    return dof


@dataclass
class Diagnostics:
    """Everything from one State, float64."""

    time: float  # ps
    step: int
    linear_momentum: np.ndarray  # amu nm/ps
    angular_momentum: np.ndarray  # about the centre of mass, amu nm^2/ps
    angular_momentum_origin: np.ndarray
    kinetic: float  # kJ/mol
    potential: float
    constraint_error: float  # largest relative violation

    @property
    def total(self) -> float:
        return self.kinetic + self.potential


def diagnostics(obj, system: mm.System | None = None, masses=None) -> Diagnostics:
    """All diagnostics from a single getState call on a Context (or from a State with positions,
    velocities and energy, plus its System)."""
    if isinstance(obj, app.Simulation):
        obj = obj.context
    if isinstance(obj, mm.Context):
        system = system if system is not None else obj.getSystem()
        obj = obj.getState(getPositions=True, getVelocities=True, getEnergy=True)
    x, v, m, state, system = _resolve(obj, system, masses)
    pe = state.getPotentialEnergy().value_in_unit(_KJ)
    return Diagnostics(time=state.getTime().value_in_unit(unit.picosecond), step=int(state.getStepCount()),
                       linear_momentum=_linear(v, m), angular_momentum=_angular(x, v, m, "com"),
                       angular_momentum_origin=_angular(x, v, m, "origin"),
                       kinetic=float(0.5 * (m[:, None] * v * v).sum()), potential=pe,
                       constraint_error=_constraint_violation(x, system))
