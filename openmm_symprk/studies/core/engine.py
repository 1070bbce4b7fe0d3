"""One row running from a state of a scene, sampled as a study needs it (the equipartition and fidelity studies).

:class:`RowEngine` builds the row's System (:meth:`~.rows.Row.system_for`: HMR, MTS force groups) and integrator
(:meth:`~.rows.Row.build`), or for a ``rigid:`` row the rigid-body engine
(:class:`~openmm_symprk.rigid.bodies.RigidBodies`), on the CPU platform, and starts it from (x, v) as given (the
velocities of an HMR row carried over to its masses by
:func:`~openmm_symprk.systems.repartition.rigid_velocities_for_masses`).
"""
from __future__ import annotations

import numpy as np
import openmm as mm
import openmm.unit as unit

from ...systems.properties import masses
from .rows import Row

__all__ = ["RowEngine"]


class RowEngine:
    """``row`` running from the state (x, v) of ``scene`` (a Scene with a topology); ``masses``: the row's masses."""

    def __init__(self, scene, x, v, row: Row, seed: int = 1, threads: int = 1):
        self.row = row
        props = {"Threads": str(threads)}
        if row.is_rigid:
            from ...rigid.bodies import RigidBodies

            self.system, self.masses, self.integrator, self.context = scene.system, scene.masses(), None, None
            self.rigid = RigidBodies(scene.system, x, v, scene.molecules, row.h_ps, row.method, "CPU", props)
            return
        self.rigid = None
        self.system = row.system_for(scene.system, scene.topology)
        self.masses = masses(self.system)
        if row.hmr_da is not None:
            from ...systems.repartition import rigid_velocities_for_masses

            v = rigid_velocities_for_masses(x, v, scene.masses(), self.masses, scene.molecules)
        self.integrator = row.build(self.system, seed=seed)
        self.context = mm.Context(self.system, self.integrator, mm.Platform.getPlatformByName("CPU"), props)
        self.context.setPositions(x)
        self.context.setVelocities(v)

    def step(self, n: int):
        (self.rigid or self.integrator).step(int(n))

    def heat_bath(self) -> float | None:
        """The heat bath's energy (kJ/mol): 0 for NVE, None for a thermostat that reports none."""
        if self.row.ensemble == "NVE":
            return 0.0
        if not self.row.has_heat_bath:
            return None
        e = self.integrator.computeHeatBathEnergy()
        return float(e.value_in_unit(unit.kilojoule_per_mole) if unit.is_quantity(e) else e)

    def sample(self, velocities: bool = True, energy: bool = True):
        """(x nm, v nm/ps or None, potential energy kJ/mol or None) now."""
        if self.rigid is not None:
            return (self.rigid.positions(), self.rigid.velocities() if velocities else None,
                    self.rigid.potential_energy() if energy else None)
        st = self.context.getState(getPositions=True, getVelocities=velocities, getEnergy=energy)
        x = np.asarray(st.getPositions(asNumpy=True).value_in_unit(unit.nanometer))
        v = np.asarray(st.getVelocities(asNumpy=True).value_in_unit(unit.nanometer / unit.picosecond)) \
            if velocities else None
        pe = st.getPotentialEnergy().value_in_unit(unit.kilojoule_per_mole) if energy else None
        return x, v, pe
