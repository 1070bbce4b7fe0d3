"""A free rigid body in OpenMM, the scene of the cross-validation against the exact solution of Euler's equations
(:func:`openmm_symprk.rigid.lie_poisson.exact_solution`): one rigid molecule (:func:`.groups.make_rigid`), torque-free
in vacuum, spinning, run through RATTLE by :class:`~openmm_symprk.integrators.SymplecticIntegrator`; and the two
molecules it is tried on (a water, a planar top; H2O2, a non-planar one)."""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np
import openmm as mm
import openmm.unit as unit

from ..physics.rigid_motion import body_angular_momentum, principal_axes, rigid_body_velocities
from .groups import RigidGroup, make_rigid, positions_nm

__all__ = ["rigid_water", "hydrogen_peroxide", "FreeRigidBody", "free_rigid_body", "run_free_rigid_body"]


def _f32(x: float) -> float:
    return float(np.float32(x))


def rigid_water(center=(0.0, 0.0, 0.0)):
    """(positions nm, masses Da) of a TIP3P-geometry water, an asymmetric (planar) top.

    OpenMM's Reference/CPU SETTLE stores the constraint distances in single precision, so the O-H and
    H-H distances are chosen float32-exact: the geometry SETTLE keeps is then the input geometry."""
    d_oh, d_hh = _f32(0.09572), _f32(0.15139)
    c = 1.0 - d_hh * d_hh / (2.0 * d_oh * d_oh)
    pos = np.array([[0.0, 0.0, 0.0], [d_oh, 0.0, 0.0], [d_oh * c, d_oh * np.sqrt(1.0 - c * c), 0.0]])
    return pos + np.asarray(center, float), np.array([15.999, 1.008, 1.008])


def hydrogen_peroxide(center=(0.0, 0.0, 0.0)):
    """(positions nm, masses Da) of an H2O2-like molecule: 4 atoms, non-planar, asymmetric top."""
    d_oo, d_oh = 0.1475, 0.0950
    theta, phi = np.deg2rad(94.8), np.deg2rad(111.5)
    o1, o2 = np.zeros(3), np.array([d_oo, 0.0, 0.0])
    h1 = o1 + d_oh * np.array([-np.cos(theta), np.sin(theta), 0.0])
    h2 = o2 + d_oh * np.array([np.cos(theta), np.sin(theta) * np.cos(phi), np.sin(theta) * np.sin(phi)])
    return np.array([o1, o2, h1, h2]) + np.asarray(center, float), np.array([15.999, 15.999, 1.008, 1.008])


@dataclass
class FreeRigidBody:
    """A single rigid molecule, torque-free in vacuum, spinning: the scene of the cross-validation."""

    system: mm.System
    positions: np.ndarray  # nm
    velocities: np.ndarray  # nm/ps, a rigid rotation
    masses: np.ndarray
    body_coords: np.ndarray  # positions - com in the principal frame at t = 0
    moments: np.ndarray  # principal moments (Da nm²), ascending
    x0: np.ndarray  # body angular momentum at t = 0 (Da nm²/ps)
    group: RigidGroup

    def body_angular_momentum(self, positions, velocities):
        """(x, L): body-frame and space-frame angular momentum of a state."""
        x, L, _ = body_angular_momentum(self.body_coords, positions, velocities, self.masses)
        return x, L


def free_rigid_body(positions, masses, body_angular_velocity) -> FreeRigidBody:
    """A System holding one rigid molecule (no forces) and a state spinning at ``body_angular_velocity``
    (1/ps, along the principal axes, ascending moments), so that x0 = M ω."""
    pos = positions_nm(positions)
    m = np.asarray(masses, float)
    system = mm.System()
    for mi in m:
        system.addParticle(float(mi))
    (group,) = make_rigid(system, pos, [list(range(len(pos)))])
    com, moments, axes = principal_axes(pos, m)
    w = np.asarray(body_angular_velocity, float)
    vel = rigid_body_velocities(pos, m, axes @ w)
    return FreeRigidBody(system, pos, vel, m, (pos - com) @ axes, moments, moments * w, group)


def run_free_rigid_body(body: FreeRigidBody, method: str, step_ps: float, n_steps: int, record_every: int = 0,
                        platform: str = "Reference", constraint_tolerance: float = 1e-12):
    """Integrate ``body`` with SymplecticIntegrator(method) through RATTLE.

    Returns (times ps, x body-frame angular momenta, L space-frame angular momenta), recorded every
    ``record_every`` steps (0: only the start and the end)."""
    from ..integrators import SymplecticIntegrator

    integrator = SymplecticIntegrator(step_ps, method, system=body.system)
    integrator.setConstraintTolerance(constraint_tolerance)
    ctx = mm.Context(body.system, integrator, mm.Platform.getPlatformByName(platform))
    ctx.setPositions(body.positions)
    ctx.setVelocities(body.velocities)
    every = record_every if record_every > 0 else n_steps
    times, xs, Ls = [], [], []
    done = 0

    def record():
        st = ctx.getState(getPositions=True, getVelocities=True)
        x, L = body.body_angular_momentum(st.getPositions(asNumpy=True).value_in_unit(unit.nanometer),
                                          st.getVelocities(asNumpy=True).value_in_unit(unit.nanometer / unit.picosecond))
        times.append(done * step_ps)
        xs.append(x)
        Ls.append(L)

    record()
    while done < n_steps:
        k = min(every, n_steps - done)
        integrator.step(k)
        done += k
        record()
    ctx = None  # released before returning (record() holds the name)
    return np.array(times), np.array(xs), np.array(Ls)
