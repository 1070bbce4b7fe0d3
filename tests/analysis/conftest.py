"""A trajectory no code of this package wrote: 64 SPC/E waters run by OpenMM's own VerletIntegrator under
app.Simulation, positions written by OpenMM's DCDReporter (wrapped into the box, float32 Angstrom) with a PDB
topology from OpenMM's PDBFile, and the same frames' positions and velocities kept in memory in float64
(continuous, as the fidelity study keeps them)."""
import numpy as np
import openmm as mm
import openmm.app as app
import openmm.unit as unit
import pytest


class PlainTrajectory:
    """Files (pdb, dcd), the in-memory frames x, v (F, N, 3) nm and nm/ps, dt (ps), box (3,) nm, masses (N,),
    charges (N,), molecules (n, 3) and the System."""


@pytest.fixture(scope="session")
def plain_water(tmp_path_factory):
    from openmm_symprk.systems.prepare import equilibrate, minimise
    from openmm_symprk.systems.properties import masses
    from openmm_symprk.systems.scenes import water_box

    system, topology, positions = water_box("spce", n_waters=64, cutoff_nm=0.55)
    x0, v0 = equilibrate(system, minimise(system, positions, max_iterations=100), 300.0, 2.0, seed=3)
    folder = tmp_path_factory.mktemp("plain_openmm")
    out = PlainTrajectory()
    out.pdb, out.dcd = str(folder / "water.pdb"), str(folder / "water.dcd")
    sim = app.Simulation(topology, system, mm.VerletIntegrator(2 * unit.femtoseconds),
                         mm.Platform.getPlatformByName("CPU"), {"Threads": "1"})
    sim.context.setPositions(x0)
    sim.context.setVelocities(v0)
    with open(out.pdb, "w") as fh:
        app.PDBFile.writeFile(topology, x0 * unit.nanometer, fh)
    every, n_frames = 5, 600  # a frame every 10 fs, 6 ps
    reporter = app.DCDReporter(out.dcd, every)
    sim.reporters.append(reporter)
    xs, vs = [], []
    for _ in range(n_frames):
        sim.step(every)
        state = sim.context.getState(getPositions=True, getVelocities=True)
        xs.append(state.getPositions(asNumpy=True).value_in_unit(unit.nanometer))
        vs.append(state.getVelocities(asNumpy=True).value_in_unit(unit.nanometer / unit.picosecond))
    sim.reporters.clear()
    del reporter, sim  # DCDReporter closes its file when it is deleted (it has no close())
    out.x, out.v, out.dt = np.array(xs), np.array(vs), every * 0.002
    out.box = np.array([system.getDefaultPeriodicBoxVectors()[k][k].value_in_unit(unit.nanometer) for k in range(3)])
    out.masses = masses(system)
    nb = next(f for f in system.getForces() if isinstance(f, mm.NonbondedForce))
    out.charges = np.array([nb.getParticleParameters(i)[0].value_in_unit(unit.elementary_charge)
                            for i in range(system.getNumParticles())])
    out.molecules = np.array([[a.index for a in r.atoms()] for r in topology.residues()])
    out.system, out.topology = system, topology
    return out
