"""Hydrogen mass repartitioning of rigid water and an equilibrium state carried over to the new masses."""
import numpy as np
import pytest

from openmm_symprk.physics.momenta import molecule_frames
from openmm_symprk.physics.temperature import R_KJ
from openmm_symprk.systems.prepare import maxwell_boltzmann
from openmm_symprk.systems.properties import masses
from openmm_symprk.systems.repartition import repartition_hydrogen_mass, rigid_velocities_for_masses
from openmm_symprk.systems.scenes import water_box


@pytest.fixture(scope="module")
def box():
    system, topology, x = water_box("spce", 64, 0.55)
    return system, topology, x, maxwell_boltzmann(system, x, 300.0, seed=5)


def test_hydrogens_take_mass_from_their_oxygen_rigid_water_included(box):
    system, topology, _, _ = box
    new = repartition_hydrogen_mass(system, topology, 3.0)
    m0, m = masses(system), masses(new)
    np.testing.assert_allclose(m.reshape(-1, 3).sum(axis=1), m0.reshape(-1, 3).sum(axis=1), rtol=1e-14)
    assert np.all(m.reshape(-1, 3)[:, 1:] == 3.0) and masses(system)[1] == pytest.approx(1.008, abs=1e-3)  # a copy
    assert new.getNumConstraints() == system.getNumConstraints()
    with pytest.raises(ValueError, match="hydrogen_mass must be between 1 and 5 Da"):
        repartition_hydrogen_mass(system, topology, 9.0)


def test_velocities_for_new_masses_keep_each_molecules_motion_and_energy(box):
    system, topology, x, v = box
    m0, m1 = masses(system), masses(repartition_hydrogen_mass(system, topology, 3.0))
    mols = np.arange(len(x)).reshape(-1, 3)
    out = rigid_velocities_for_masses(x, v, m0, m1, mols)
    old, new = molecule_frames(x, v, m0, mols), molecule_frames(x, out, m1, mols)
    np.testing.assert_allclose(new.V, old.V, atol=1e-12)  # each molecule's centre-of-mass velocity
    rot = lambda fr: 0.5 * np.einsum("ni,ni->n", fr.L, np.linalg.solve(fr.inertia, fr.L[..., None])[..., 0])
    np.testing.assert_allclose(rot(new), rot(old), rtol=1e-10)  # each molecule's rotational kinetic energy
    for i, j in ((0, 1), (0, 2), (1, 2)):  # still a rigid motion: no velocity along any bond
        d = x[mols[:, j]] - x[mols[:, i]]
        dv = out[mols[:, j]] - out[mols[:, i]]
        assert np.abs((d * dv).sum(axis=1)).max() < 1e-10
    with pytest.raises(ValueError, match="total mass"):
        rigid_velocities_for_masses(x, v, m0, m1 * 1.1, mols)


def test_the_map_carries_the_maxwell_boltzmann_distribution_over():
    """omega ~ N(0, kT I_old^-1) becomes omega ~ N(0, kT I_new^-1): checked on 20000 draws of one molecule."""
    rng = np.random.default_rng(11)
    x = np.array([[0.0, 0.0, 0.0], [0.1, 0.0, 0.0], [-0.0333, 0.0943, 0.0]])
    m0, m1 = np.array([16.0, 1.0, 1.0]), np.array([12.0, 3.0, 3.0])
    i_old = molecule_frames(x, np.zeros_like(x), m0, [[0, 1, 2]]).inertia[0]
    i_new = molecule_frames(x, np.zeros_like(x), m1, [[0, 1, 2]]).inertia[0]
    kT = R_KJ * 300.0
    w = rng.multivariate_normal(np.zeros(3), kT * np.linalg.inv(i_old), size=20000)
    com0 = (m0[:, None] * x).sum(0) / m0.sum()
    out = []
    for wk in w[:2000]:
        v = np.cross(wk, x - com0)
        vn = rigid_velocities_for_masses(x, v, m0, m1, [[0, 1, 2]])
        fr = molecule_frames(x, vn, m1, [[0, 1, 2]])
        out.append(np.linalg.solve(fr.inertia[0], fr.L[0]))
    cov = np.cov(np.array(out).T)
    expected = kT * np.linalg.inv(i_new)
    assert np.abs(cov - expected).max() < 0.1 * np.abs(expected).max()
