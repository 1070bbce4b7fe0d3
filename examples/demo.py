"""The main example as a plain script: a spinning rigid-water cluster in vacuum.

Copy the pattern: build (or load) a System, pass it to SymplecticIntegrator so that RATTLE steps are
compiled for its constraints and anything that breaks conservation is reported, then use the
integrator like any OpenMM integrator.

    python examples/demo.py [method] [platform]
"""
import sys

import numpy as np
import openmm as mm
import openmm.app as app
import openmm.unit as unit

from openmm_symprk import SymplecticIntegrator
from openmm_symprk.systems.scenes import water_cluster

method = sys.argv[1] if len(sys.argv) > 1 else "yoshida-4"
platform = sys.argv[2] if len(sys.argv) > 2 else "Reference"

scene = water_cluster(64)  # rigid TIP3P (SETTLE), no cutoff, no box, no CMMotionRemover
integrator = SymplecticIntegrator(2 * unit.femtoseconds, method, system=scene.system)
print(integrator.describe())

simulation = app.Simulation(scene.topology, scene.system, integrator, mm.Platform.getPlatformByName(platform))
simulation.context.setPositions(scene.positions)
simulation.context.setVelocities(scene.velocities)
simulation.reporters.append(app.StateDataReporter(sys.stdout, 500, step=True, time=True, potentialEnergy=True,
                                                  totalEnergy=True, temperature=True))
masses = scene.masses()[:, None]


def angular_momentum():
    state = simulation.context.getState(getPositions=True, getVelocities=True)
    x = state.getPositions(asNumpy=True).value_in_unit(unit.nanometer)
    v = state.getVelocities(asNumpy=True).value_in_unit(unit.nanometer / unit.picosecond)
    return (masses * np.cross(x, v)).sum(axis=0)


L0 = angular_momentum()
simulation.step(2000)
L1 = angular_momentum()
print(f"|dL|/|L| after 2000 steps: {np.linalg.norm(L1 - L0) / np.linalg.norm(L0):.2e}")
