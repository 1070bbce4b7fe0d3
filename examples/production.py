"""The recommended production set-up (README's first example) as a script: a solvated protein with amber14 and TIP3P,
PME, HBonds constraints and rigid water, NVT at 300 K with the package's thermostat, and the method and step
docs/production.md recommends for it ("What to run").

OpenMM's own solvated villin (test.pdb: 8,867 atoms, the box the recommendation was measured on) stands in for your
system; give your own solvated PDB with --pdb (and --minimize, unless it is equilibrated already).

    python examples/production.py [--pdb solvated.pdb --minimize] [--steps 5000] [--platform CPU] [--quick]
"""
import argparse
import sys

import openmm as mm
import openmm.app as app
import openmm.unit as unit

from openmm_symprk import SymplecticIntegrator
from openmm_symprk.systems.scenes import openmm_data

parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
parser.add_argument("--pdb", default=openmm_data("test.pdb"), help="a solvated system (default: OpenMM's villin)")
parser.add_argument("--minimize", action="store_true", help="minimize the energy first (a structure of your own)")
parser.add_argument("--steps", type=int, default=5000, help="steps of 2 fs (default 5000: 10 ps)")
parser.add_argument("--platform", default="CPU", help="an OpenMM platform (CPU, CUDA, OpenCL)")
parser.add_argument("--quick", action="store_true", help="100 steps (seconds, for the test-suite)")
args = parser.parse_args()
steps = 100 if args.quick else args.steps

pdb = app.PDBFile(args.pdb)
forcefield = app.ForceField("amber14-all.xml", "amber14/tip3p.xml")
system = forcefield.createSystem(pdb.topology, nonbondedMethod=app.PME, nonbondedCutoff=0.9*unit.nanometer,
                                 constraints=app.HBonds)
integrator = SymplecticIntegrator(2*unit.femtoseconds, "verlet", system=system, temperature=300*unit.kelvin)
print(integrator.describe())

simulation = app.Simulation(pdb.topology, system, integrator, mm.Platform.getPlatformByName(args.platform))
simulation.context.setPositions(pdb.positions)
if args.minimize:
    simulation.minimizeEnergy()
simulation.context.setVelocitiesToTemperature(300*unit.kelvin)
simulation.reporters.append(app.StateDataReporter(sys.stdout, max(steps // 5, 1), step=True, potentialEnergy=True,
                                                  temperature=True, speed=True))
simulation.step(steps)
