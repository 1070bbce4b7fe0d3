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
float32 (DCD, TRR, XTC) limits them to ~1e-7 relative (see :mod:`openmm_symprk.conservation.analysis`).
"""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np
import openmm as mm
import openmm.app as app
import openmm.unit as unit

from ..physics import momenta, temperature
from ..systems.properties import constraint_violation as _violation
from ..systems.properties import degrees_of_freedom, masses, molecules

_NM = unit.nanometer
_NM_PS = unit.nanometer / unit.picosecond
_KJ = unit.kilojoule_per_mole

__all__ = ["masses_of", "linear_momentum", "angular_momentum", "molecules", "molecule_angular_momentum",
           "kinetic_energy", "kinetic_temperatures", "energies", "constraint_violation", "degrees_of_freedom",
           "Diagnostics", "diagnostics"]

#: The System's masses (Da) -- the same function as openmm_symprk.systems.properties.masses.
masses_of = masses


# -- inputs ---------------------------------------------------------------------------------------
def _array(q, u) -> np.ndarray:
    if unit.is_quantity(q):
        q = q.value_in_unit(u)
    return np.asarray(q, dtype=np.float64).reshape(-1, 3)


def _resolve(obj, system=None, masses_=None, positions=True, velocities=True, energy=False):
    """(x, v, m, state, system) from a Context, a Simulation, a State (+ System) or arrays.

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
        if masses_ is None:
            if system is None:
                raise TypeError("positions/velocities arrays need masses= or system=")
            masses_ = masses(system)
        return x, v, np.asarray(masses_, dtype=np.float64), None, system
    else:
        raise TypeError(f"expected an openmm.Context, Simulation, State or (positions, velocities), "
                        f"got {type(obj).__name__}")
    if masses_ is None:
        if system is None:
            raise TypeError("a State carries no masses: pass system= (or masses=)")
        masses_ = masses(system)
    x = state.getPositions(asNumpy=True).value_in_unit(_NM) if positions else None
    v = state.getVelocities(asNumpy=True).value_in_unit(_NM_PS) if velocities else None
    x = None if x is None else np.asarray(x, dtype=np.float64)
    v = None if v is None else np.asarray(v, dtype=np.float64)
    return x, v, np.asarray(masses_, dtype=np.float64), state, system


# -- momentum maps ----------------------------------------------------------------------------
def linear_momentum(obj, system: mm.System | None = None, masses=None) -> np.ndarray:
    """Total linear momentum sum_i m_i v_i (Da nm/ps), float64, shape (3,)."""
    _, v, m, _, _ = _resolve(obj, system, masses, positions=False)
    return momenta.linear_momentum(v, m)


def angular_momentum(obj, system: mm.System | None = None, about="com", masses=None) -> np.ndarray:
    """Total angular momentum sum_i m_i (x_i - c) x v_i (Da nm^2/ps), float64, shape (3,).

    ``about``: "com" (the centre of mass, default here), "origin", or a point in nm.  In an isolated
    system both L about the centre of mass and L about the origin are conserved (L_origin = L_com +
    M r_cm x V_cm, with V_cm constant); a CMMotionRemover keeps the first and changes the second."""
    x, v, m, _, _ = _resolve(obj, system, masses)
    return momenta.angular_momentum(x, v, m, about=about)


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
            out[k] = momenta.angular_momentum(x[g], v[g], mg, about="com")
    return out


def kinetic_temperatures(obj, system: mm.System | None = None, groups=None, momentum_fixed: bool = True,
                         masses=None):
    """Translational and rotational (and internal) kinetic temperature of the molecules, in K
    (:class:`openmm_symprk.physics.temperature.KineticTemperatures`).

    ``groups``: lists of particle indices (default: the molecules of the Context or System); every distance
    constraint of the System is inside a molecule and removes an internal degree of freedom.
    ``momentum_fixed``: the total momentum is conserved or removed (NVE without external forces, or a
    CMMotionRemover): translation then has 3 N_mol - 3 degrees of freedom.  Positions must keep molecules whole
    (OpenMM's State does unless asked to wrap them)."""
    x, v, m, _, system = _resolve(obj, system, masses)
    if groups is None:
        src = obj.context if isinstance(obj, app.Simulation) else obj
        groups = molecules(src if isinstance(src, mm.Context) else system)
    n_constraints = system.getNumConstraints() if system is not None else 0
    return temperature.kinetic_temperatures(x, v, m, [list(g) for g in groups], momentum_fixed, n_constraints)


# -- energies and constraints --------------------------------------------------------------------
def kinetic_energy(obj, system: mm.System | None = None, masses=None) -> float:
    """1/2 sum m v^2 (kJ/mol) in float64 from the current velocities (on-step velocities for
    CustomIntegrators; VerletIntegrator's leapfrog state holds half-step velocities)."""
    _, v, m, _, _ = _resolve(obj, system, masses, positions=False)
    return momenta.kinetic_energy(v, m)


def energies(obj, system: mm.System | None = None, masses=None) -> dict:
    """{'kinetic', 'potential', 'total'} in kJ/mol: kinetic in float64 from the velocities, potential
    from OpenMM (needs a Context or a State made with getEnergy=True)."""
    if isinstance(obj, app.Simulation):
        obj = obj.context
    if isinstance(obj, mm.Context):
        system = system if system is not None else obj.getSystem()
        obj = obj.getState(getVelocities=True, getEnergy=True)
    _, v, m, state, _ = _resolve(obj, system, masses, positions=False)
    ke = momenta.kinetic_energy(v, m)
    pe = state.getPotentialEnergy().value_in_unit(_KJ)
    return {"kinetic": ke, "potential": pe, "total": ke + pe}


def constraint_violation(obj, system: mm.System | None = None) -> float:
    """Largest relative constraint violation max_k |r_k - d_k| / d_k (0 without constraints)."""
    x, _, _, _, system = _resolve(obj, system, np.zeros(0), velocities=False)
    if system is None:
        raise TypeError("a State carries no constraints: pass system=")
    return _violation(x, system)


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
                       linear_momentum=momenta.linear_momentum(v, m),
                       angular_momentum=momenta.angular_momentum(x, v, m, about="com"),
                       angular_momentum_origin=momenta.angular_momentum(x, v, m, about="origin"),
                       kinetic=momenta.kinetic_energy(v, m), potential=pe,
                       constraint_error=_violation(x, system))
