"""<w^2> per degree of freedom from forces at canonical configurations (openmm_symprk.systems.frequencies), against
systems whose frequencies are known exactly, with and without a constraint."""
import numpy as np
import openmm as mm
import pytest

from openmm_symprk.systems.frequencies import mean_square_frequency

KB = 0.00831446261815324


def _wells(n, k, mass, constrain):
    system = mm.System()
    well = mm.CustomExternalForce("0.5*k*(x^2+y^2+z^2)")
    well.addGlobalParameter("k", k)
    for i in range(n):
        system.addParticle(mass)
        well.addParticle(i, [])
    system.addForce(well)
    if constrain:
        system.addConstraint(0, 1, 0.2)
    return system


def test_independent_harmonic_particles_give_k_over_m():
    k, m, t = 500.0, 4.0, 300.0
    rng = np.random.default_rng(1)
    configs = [rng.normal(0, np.sqrt(KB * t / k), (50, 3)) for _ in range(40)]
    got = mean_square_frequency(_wells(50, k, m, False), configs, t)
    assert got["all"] == pytest.approx(k / m, rel=0.03) and got["configurations"] == 40


def test_a_rigid_rod_in_an_isotropic_well_moves_only_its_centre_of_mass():
    """Two equal masses on a rod of length d, each in the well k: the centre of mass oscillates at k/m (3 degrees of
    freedom) and the rod turns freely (the well's energy does not depend on its orientation, 2 degrees of freedom at
    w = 0): <w^2> = 3/5 k/m, 'trans' k/m, 'rot' 0 -- only once the force along the rod is projected out."""
    k, m, t, d = 500.0, 4.0, 300.0, 0.2
    rng = np.random.default_rng(2)
    configs = []
    for _ in range(400):
        centre = rng.normal(0, np.sqrt(KB * t / (2 * k)), 3)
        u = rng.normal(size=3)
        u /= np.linalg.norm(u)
        configs.append(np.array([centre + u * d / 2, centre - u * d / 2]))
    got = mean_square_frequency(_wells(2, k, m, True), configs, t, molecules=[[0, 1]])
    assert got["trans"] == pytest.approx(k / m, rel=0.1)
    assert abs(got["rot"]) < 1e-6 * k / m
    assert got["all"] == pytest.approx(0.6 * k / m, rel=0.1)


def test_no_configuration_is_refused():
    with pytest.raises(ValueError, match="no configuration"):
        mean_square_frequency(_wells(2, 1.0, 1.0, False), [], 300.0)
