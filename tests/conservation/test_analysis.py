"""MDAnalysis momentum analysis on a written TRR against in-process float64 values.

The trajectory stores float32, so per-frame values agree with the in-process ones to ~1e-7
relative (FLOAT32_FLOOR), and a drift measured from the file cannot go below that floor."""
import numpy as np
import openmm as mm
import openmm.app as app
import pytest

from openmm_symprk import SymplecticIntegrator
from openmm_symprk.analysis.universe import KineticTemperatures
from openmm_symprk.conservation.analysis import FLOAT32_FLOOR, AngularMomentum, LinearMomentum, universe
from openmm_symprk.conservation import (angular_momentum, kinetic_temperatures, linear_momentum,
                                        molecule_angular_momentum)
from openmm_symprk.conservation.reporters import VelocityTRRReporter, write_topology

pytestmark = [pytest.mark.filterwarnings("ignore:Reload offsets"), pytest.mark.filterwarnings("ignore:Reader has no dt")]


def _record(scene, path, integrator=None, frames=6, every=20):
    ig = integrator or SymplecticIntegrator(0.002, "verlet", system=scene.system)
    sim = app.Simulation(scene.topology, scene.system, ig, mm.Platform.getPlatformByName("Reference"))
    sim.context.setPositions(scene.positions)
    sim.context.setVelocities(scene.velocities)
    rep = VelocityTRRReporter(str(path), every)
    sim.reporters.append(rep)
    L, P, Lm, T = [], [], [], []
    for _ in range(frames):
        sim.step(every)
        L.append(angular_momentum(sim.context))
        P.append(linear_momentum(sim.context))
        Lm.append(molecule_angular_momentum(sim.context))
        t = kinetic_temperatures(sim.context)
        T.append((t.translational, t.rotational))
    rep.close()
    return np.array(L), np.array(P), np.array(Lm), np.array(T)


@pytest.fixture(scope="module")
def recorded(tmp_path_factory, water8_module):
    path = tmp_path_factory.mktemp("trr") / "w.trr"
    return path, _record(water8_module, path)


@pytest.fixture(scope="module")
def water8_module():
    from openmm_symprk.systems.scenes import water_cluster

    return water_cluster(8)


def test_matches_in_process_to_float32_floor(recorded, water8_module):
    path, (L, P, Lm, _) = recorded
    u = universe(water8_module.topology, str(path), system=water8_module.system)
    a = AngularMomentum(u.atoms, by="residues").run()
    p = LinearMomentum(u.atoms).run()
    nL = np.linalg.norm(L[0])
    err = np.abs(a.results.total - L).max() / nL
    assert err < 10 * FLOAT32_FLOOR, err  # measured ~3e-8
    assert np.abs(a.results.groups - Lm).max() < 10 * FLOAT32_FLOOR * np.abs(Lm).max()
    pscale = float((water8_module.masses()[:, None] * np.abs(water8_module.velocities)).sum())
    assert np.abs(p.results.total - P).max() < 10 * FLOAT32_FLOOR * pscale
    # in process L is conserved to ~1e-14; from the file the drift sits at the float32 floor
    assert np.linalg.norm(L[-1] - L[0]) / nL < 1e-12
    assert np.all(a.results.relative_drift < 10 * FLOAT32_FLOOR)
    assert np.allclose(a.times, 0.04 * np.arange(1, 7), rtol=1e-6)


def test_guessed_masses_are_not_the_system_masses(recorded, water8_module, tmp_path):
    """A PDB-based Universe guesses element masses (differ by up to 0.003 amu): its L is not the
    conserved one; masses=System fixes it."""
    import MDAnalysis as mda

    path, (L, _, _, _) = recorded
    pdb = str(tmp_path / "w.pdb")
    write_topology(pdb, water8_module.topology, water8_module.positions)
    u = mda.Universe(pdb, str(path))
    nL = np.linalg.norm(L[0])
    guessed = np.abs(AngularMomentum(u.atoms).run().results.total - L).max() / nL
    exact = np.abs(AngularMomentum(u.atoms, masses=water8_module.system).run().results.total - L).max() / nL
    assert guessed > 1e-6 and exact < 10 * FLOAT32_FLOOR, (guessed, exact)


def test_fragments_and_origin(recorded, water8_module):
    path, (L, _, _, _) = recorded
    u = universe(water8_module.topology, str(path), system=water8_module.system)
    frag = AngularMomentum(u.atoms, by="fragments").run()
    assert frag.results.groups.shape == (6, 8, 3)
    origin = AngularMomentum(u.atoms, about="origin").run()
    assert origin.results.total.shape == (6, 3)


def test_thermostat_drift_is_far_above_the_floor(water8_module, tmp_path):
    ig = mm.LangevinMiddleIntegrator(150, 5.0, 0.002)
    path = tmp_path / "lang.trr"
    _record(water8_module, path, integrator=ig)
    u = universe(water8_module.topology, str(path), system=water8_module.system)
    assert AngularMomentum(u.atoms).run().results.relative_drift[-1] > 1e4 * FLOAT32_FLOOR


def test_no_velocities_is_an_error(water8_module, tmp_path):
    import MDAnalysis as mda

    pdb = str(tmp_path / "w.pdb")
    write_topology(pdb, water8_module.topology, water8_module.positions)
    with pytest.raises(ValueError, match="no velocities"):
        AngularMomentum(mda.Universe(pdb).atoms).run()


def test_kinetic_temperatures_from_a_trajectory_match_the_live_ones(recorded, water8_module):
    path, (_, _, _, T) = recorded
    u = universe(water8_module.topology, str(path), system=water8_module.system)
    k = KineticTemperatures(u.atoms, masses=water8_module.system).run()
    np.testing.assert_allclose(k.results.translational, T[:, 0], rtol=1e-5)
    np.testing.assert_allclose(k.results.rotational, T[:, 1], rtol=1e-5)
    assert k.results.dof == {"translational": 21, "rotational": 24, "internal": 0}
    assert k.results.mean_difference == pytest.approx(float(np.mean(T[:, 1] - T[:, 0])), rel=1e-4)
