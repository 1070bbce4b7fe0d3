"""Initial states for a System: energy minimisation, constrained velocities, seeded Maxwell-Boltzmann
velocities (optionally spun about the centre of mass).  Units: nm, nm/ps, K."""
from __future__ import annotations

import numpy as np
import openmm as mm
import openmm.unit as unit

from ..physics import centre_of_mass
from ..physics.temperature import R_KJ
from .properties import has_constraints, masses
from ..support.errors import InputError

__all__ = ["positions_nm", "minimise", "constrain_velocities", "maxwell_boltzmann", "equilibrate", "without_net_momentum",
           "R_KJ"]


def _context(system, platform="Reference", properties=None):
    plat = mm.Platform.getPlatformByName(platform) if isinstance(platform, str) else platform
    return mm.Context(system, mm.VerletIntegrator(0.001), plat, properties or {})


def positions_nm(positions) -> np.ndarray:
    """One set of positions (a Quantity, a list of Vec3 or of triples in nm, an array) as an (N, 3) array in nm."""
    if unit.is_quantity(positions):
        positions = positions.value_in_unit(unit.nanometer)
    return np.array([[float(c) for c in p] for p in positions]) if not isinstance(positions, np.ndarray) \
        else np.asarray(positions, dtype=np.float64)


def minimise(system: mm.System, positions, platform="Reference", tolerance: float = 10.0,
             max_iterations: int = 200, properties=None) -> np.ndarray:
    """Constrained, energy-minimised positions (nm): constraints applied to 1e-10, then OpenMM's
    LocalEnergyMinimizer to ``tolerance`` kJ/mol/nm or ``max_iterations`` iterations (it keeps the constraints
    to the Context's constraint tolerance, OpenMM's default 1e-5 relative)."""
    ctx = _context(system, platform, properties)
    try:
        ctx.setPositions(positions_nm(positions))
        if has_constraints(system):
            ctx.applyConstraints(1e-10)
        mm.LocalEnergyMinimizer.minimize(ctx, tolerance, max_iterations)
        return np.array(ctx.getState(getPositions=True).getPositions(asNumpy=True).value_in_unit(unit.nanometer))
    finally:
        del ctx


def constrain_velocities(system: mm.System, positions, velocities, tolerance: float = 1e-12) -> np.ndarray:
    """Velocities with their components along the constraints removed (so a state starts on the manifold)."""
    if not has_constraints(system):
        return np.asarray(velocities, dtype=np.float64)
    ctx = _context(system)
    try:
        ctx.setPositions(positions_nm(positions))
        ctx.setVelocities(np.asarray(velocities, dtype=np.float64))
        ctx.applyVelocityConstraints(tolerance)
        return np.array(ctx.getState(getVelocities=True).getVelocities(asNumpy=True).value_in_unit(
            unit.nanometer / unit.picosecond))
    finally:
        del ctx


def maxwell_boltzmann(system: mm.System, positions, temperature: float, seed: int,
                      angular_velocity=None) -> np.ndarray:
    """Seeded Maxwell-Boltzmann velocities at ``temperature`` (K) with zero net momentum, plus a rigid rotation
    omega x (r - r_cm) when ``angular_velocity`` (rad/ps, 3 components) is given, then constrained (nm/ps).
    Massless particles get zero velocity.  ``seed``: an int, or a numpy Generator to draw from."""
    rng = np.random.default_rng(seed)
    m = masses(system)
    x = positions_nm(positions)
    kT = R_KJ * temperature
    v = without_net_momentum(rng.normal(size=(len(m), 3)) * np.sqrt(kT / np.where(m > 0, m, 1.0))[:, None], m)
    if angular_velocity is not None:
        spin = np.cross(np.asarray(angular_velocity, dtype=float), x - centre_of_mass(x, m))
        v += np.where(m[:, None] > 0, spin, 0.0)
    v = constrain_velocities(system, x, v)
    v[m == 0] = 0.0  # the momentum correction above moved them too
    return v


def without_net_momentum(velocities, m) -> np.ndarray:
    """``velocities`` (N, 3) nm/ps less the centre-of-mass velocity P / M of the particles with mass (masses
    ``m`` (N,) Da, or a System): the total momentum is zero to round-off.  Massless particles stay at rest.
    Velocity constraints stay satisfied (a uniform translation does not change any relative velocity)."""
    m = masses(m) if isinstance(m, mm.System) else np.asarray(m, dtype=np.float64)
    v = np.array(velocities, dtype=np.float64)
    if v.shape != (len(m), 3):
        raise InputError(f"velocities must have shape ({len(m)}, 3) (one per particle), got {v.shape}")
    if not m.sum() > 0:
        raise InputError("no particle has mass: the total momentum cannot be set to zero")
    v -= (m[:, None] * v).sum(axis=0) / m.sum()
    v[m == 0] = 0.0
    return v


def equilibrate(system: mm.System, positions, temperature: float, picoseconds: float, seed: int,
                step_fs: float = 2.0, platform="CPU", properties=None):
    """(positions, velocities) after ``picoseconds`` of Langevin dynamics at ``temperature`` (friction 1/ps) from
    Maxwell-Boltzmann velocities: an equilibrated state to start NVE runs from.  The velocities are constrained
    and taken at the same time as the positions (LangevinMiddleIntegrator's are on-step)."""
    integrator = mm.LangevinMiddleIntegrator(temperature * unit.kelvin, 1.0 / unit.picosecond,
                                             step_fs * unit.femtoseconds)
    integrator.setRandomNumberSeed(seed)
    plat = mm.Platform.getPlatformByName(platform) if isinstance(platform, str) else platform
    ctx = mm.Context(system, integrator, plat, properties or {})
    try:
        x = positions_nm(positions)
        ctx.setPositions(x)
        ctx.setVelocities(maxwell_boltzmann(system, x, temperature, seed))
        integrator.step(max(0, int(round(picoseconds * 1000.0 / step_fs))))
        st = ctx.getState(getPositions=True, getVelocities=True)
        x = np.array(st.getPositions(asNumpy=True).value_in_unit(unit.nanometer))
        v = np.array(st.getVelocities(asNumpy=True).value_in_unit(unit.nanometer / unit.picosecond))
    finally:
        del ctx
    return x, constrain_velocities(system, x, v)
