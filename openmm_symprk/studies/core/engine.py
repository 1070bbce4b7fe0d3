"""One row running from a state, sampled as a study needs it: the studies' one way to set up a Context from a row.

:class:`RowEngine` builds the row's System (:meth:`~.rows.Row.system_for`: HMR, MTS force groups) and integrator
(:meth:`~.rows.Row.build`) on any platform (``"CPU"``, ``"OpenCL:mixed"``: :mod:`.platforms`), or for a ``rigid:``
row the rigid-body engine (:class:`~openmm_symprk.rigid.bodies.RigidBodies`), and starts it from (x, v): an HMR
row's velocities carried over to its masses
(:func:`~openmm_symprk.systems.repartition.rigid_velocities_for_masses`), and OpenMM's leapfrog integrators
(VerletIntegrator, LangevinMiddleIntegrator, DPDIntegrator: :attr:`~.rows.Row.leapfrog`, their State velocities
lag half a step) from v(-h/2) = v - (h/2) F(x)/m, constrained, which gives them the positions of velocity Verlet
from (x, v).  :meth:`RowEngine.sample` is the one sampler of positions, velocities and energies; with
``on_step=True`` a leapfrog row's velocities are brought to the positions' time, v + (h/2) F(x)/m constrained
(what OpenMM's own kinetic energy of these integrators shifts them by), so that an observable made of positions and
velocities together (angular velocities, temperatures) reads one time, as for the package's integrators.
"""
from __future__ import annotations

from typing import NamedTuple

import numpy as np
import openmm as mm
import openmm.unit as unit

from ...physics.momenta import kinetic_energy
from ...systems.properties import masses
from . import platforms
from .rows import Row

__all__ = ["RowEngine", "Sample"]

KJ = unit.kilojoule_per_mole


class Sample(NamedTuple):
    """A state: x (nm), v (nm/ps), pe and ke (kJ/mol; ke as the State reports it); None where not asked for."""
    x: np.ndarray | None
    v: np.ndarray | None
    pe: float | None
    ke: float | None


class RowEngine:
    """``row`` running on ``platform`` from the state (x, v) (default: the scene's own).  ``source``: a Scene (its
    topology and molecules serve HMR and rigid rows) or a System.  ``seed``: a stochastic row's random seed (default
    the row's); ``start=False`` sets (x, v) as given, also for a leapfrog row."""

    def __init__(self, row: Row, source, x=None, v=None, *, platform: str = "CPU", threads: int | None = 1,
                 seed: int | None = None, constraint_tolerance: float | None = None, start: bool = True,
                 quiet: bool = True, tolerance: float = 1e-10):
        scene = source if hasattr(source, "system") else None
        system = scene.system if scene is not None else source
        x = scene.positions if x is None else x
        v = scene.velocities if v is None else v
        name, precision = platforms.split(platform)
        self.row, self.platform = row, name
        self.lag = ()  # the kicks the State's velocities lack (Row.velocity_lag; none for the rigid-body engine)
        props = platforms.properties(name, threads, precision)
        self.integrator = self.context = self.rigid = None
        if row.is_rigid:
            from ...rigid.bodies import RigidBodies

            self.system, self.masses = system, masses(system)
            self.rigid = RigidBodies(system, x, v, scene.molecules, row.h_ps, row.method, name, props)
            return
        self.system = row.system_for(system, scene.topology if scene is not None else None)
        self.masses = masses(self.system)
        if row.hmr_da is not None:
            from ...systems.repartition import rigid_velocities_for_masses

            v = rigid_velocities_for_masses(x, v, masses(system), self.masses, scene.molecules)
        self.integrator = row.build(self.system, seed=seed, constraint_tolerance=constraint_tolerance, quiet=quiet)
        self.context = mm.Context(self.system, self.integrator, mm.Platform.getPlatformByName(name), props)
        self.context.setPositions(x)
        v = np.array(v, dtype=np.float64)
        self.lag = row.velocity_lag
        if start and self.lag:
            v = v - self.lag_kick()
        self.context.setVelocities(v)
        if start and self.lag and self.system.getNumConstraints():
            self.context.applyVelocityConstraints(tolerance)

    def step(self, n: int):
        (self.rigid or self.integrator).step(int(n))

    def advance(self, n: int):
        """``n`` steps, done when this returns: a GPU platform's queued work is waited for (for timing)."""
        self.step(n)
        if self.context is not None and self.platform != "CPU":
            self.context.getState(getPositions=True)

    def heat_bath(self) -> float | None:
        """The heat bath's energy (kJ/mol): 0 for NVE, None for a thermostat that reports none."""
        if self.row.ensemble == "NVE":
            return 0.0
        if not self.row.has_heat_bath:
            return None
        e = self.integrator.computeHeatBathEnergy()
        return float(e.value_in_unit(KJ) if unit.is_quantity(e) else e)

    def sample(self, positions: bool = True, velocities: bool = True, energy: bool = True,
               on_step: bool = False) -> Sample:
        """The state now, in float64, from one State; ``on_step``: a leapfrog row's velocities at the positions' time
        (:meth:`on_step_velocities`; the State's, half a step behind, otherwise)."""
        if self.rigid is not None:
            v = self.rigid.velocities()
            return Sample(self.rigid.positions() if positions else None, v if velocities else None,
                          self.rigid.potential_energy() if energy else None,
                          kinetic_energy(v, self.masses) if energy else None)
        shift = on_step and velocities and bool(self.lag)
        st = self.context.getState(getPositions=positions, getVelocities=velocities, getEnergy=energy)
        v = np.array(st.getVelocities(asNumpy=True).value_in_unit(unit.nanometer / unit.picosecond)) \
            if velocities else None
        if shift:
            v = self.on_step_velocities(v)
        return Sample(np.array(st.getPositions(asNumpy=True).value_in_unit(unit.nanometer)) if positions else None, v,
                      st.getPotentialEnergy().value_in_unit(KJ) if energy else None,
                      st.getKineticEnergy().value_in_unit(KJ) if energy else None)

    def lag_kick(self) -> np.ndarray:
        """The velocity change of the kicks a State's velocities lack (:attr:`~.rows.Row.velocity_lag`) at the Context's
        positions: sum over them of (fraction of h) h F_groups / m."""
        inv = np.where(self.masses > 0, 1.0 / np.where(self.masses > 0, self.masses, 1.0), 0.0)
        dv = np.zeros((len(self.masses), 3))
        for fraction, groups in self.lag:
            kw = {"groups": set(groups)} if groups is not None else {}
            f = self.context.getState(getForces=True, **kw).getForces(asNumpy=True).value_in_unit(KJ / unit.nanometer)
            dv += float(fraction) * self.row.h_ps * np.asarray(f) * inv[:, None]
        return dv

    def on_step_velocities(self, v, tolerance: float = 1e-10) -> np.ndarray:
        """A lagging row's State velocities ``v`` brought to the positions' time: v plus the kicks they lack
        (:meth:`lag_kick`; for a leapfrog integrator v + (h/2) F(x)/m, the velocity velocity Verlet has there, the mean
        of the half-step velocities on either side), projected onto the constraints (through the Context, whose
        velocities are set back as they were)."""
        shifted = v + self.lag_kick()
        if not self.system.getNumConstraints():
            return shifted
        self.context.setVelocities(shifted)
        self.context.applyVelocityConstraints(tolerance)
        out = np.array(self.context.getState(getVelocities=True).getVelocities(asNumpy=True)
                       .value_in_unit(unit.nanometer / unit.picosecond))
        self.context.setVelocities(v)
        return out
