"""Initial states: Maxwell-Boltzmann velocities (zero momentum, the temperature within its statistical error,
equipartition across masses, constraints respected, a rigid spin added exactly), constrained velocities,
minimisation lowering the energy, Langevin equilibration."""
import numpy as np
import openmm as mm

from openmm_symprk.physics.momenta import angular_momentum, centre_of_mass, inertia_tensor, kinetic_energy
from openmm_symprk.systems.prepare import (R_KJ, constrain_velocities, equilibrate, maxwell_boltzmann, minimise)
from openmm_symprk.systems.properties import constraint_violation, degrees_of_freedom, masses


def _gas(n=2000, seed=0):
    """``n`` free particles, half of mass 1 Da and half of 100 Da, a few massless ones (no forces)."""
    rng = np.random.default_rng(seed)
    system = mm.System()
    m = np.where(np.arange(n) % 2 == 0, 1.0, 100.0)
    m[:3] = 0.0
    for mi in m:
        system.addParticle(mi)
    return system, rng.uniform(0, 5, (n, 3))


def _temperature(v, m, dof):
    return 2 * kinetic_energy(v, m) / (dof * R_KJ)


def test_maxwell_boltzmann_temperature_within_its_statistical_error():
    system, x = _gas()
    m = masses(system)
    v = maxwell_boltzmann(system, x, 300.0, seed=11)
    dof = degrees_of_freedom(system) - 3  # the net momentum is removed
    # 2 KE / kT is chi-squared with dof degrees of freedom: relative standard deviation sqrt(2 / dof)
    assert abs(_temperature(v, m, dof) - 300.0) < 4 * 300.0 * np.sqrt(2 / dof)
    # equipartition: light and heavy particles at the same temperature (a wrong mass scaling would split them)
    for heavy in (False, True):
        sel = (m == 100.0) if heavy else (m == 1.0)
        assert abs(_temperature(v[sel], m[sel], 3 * sel.sum()) - 300.0) < 4 * 300.0 * np.sqrt(2 / (3 * sel.sum()))


def test_maxwell_boltzmann_mean_temperature_over_seeds():
    """20 seeds: the mean temperature within 4 standard errors of the target (bias of the sampler)."""
    system, x = _gas(400)
    m = masses(system)
    dof = degrees_of_freedom(system) - 3
    temps = [_temperature(maxwell_boltzmann(system, x, 150.0, seed=s), m, dof) for s in range(20)]
    assert abs(np.mean(temps) - 150.0) < 4 * 150.0 * np.sqrt(2 / dof) / np.sqrt(20)


def test_maxwell_boltzmann_zero_momentum_massless_still_and_seeded():
    system, x = _gas()
    m = masses(system)
    v = maxwell_boltzmann(system, x, 300.0, seed=5)
    p_scale = np.sum(m[:, None] * np.abs(v))
    assert np.abs((m[:, None] * v).sum(0)).max() < 1e-13 * p_scale
    assert np.all(v[m == 0] == 0.0)
    np.testing.assert_array_equal(v, maxwell_boltzmann(system, x, 300.0, seed=5))
    assert not np.allclose(v, maxwell_boltzmann(system, x, 300.0, seed=6))
    rng = np.random.default_rng(5)  # a Generator is drawn from, as the seed it was made from
    np.testing.assert_array_equal(v, maxwell_boltzmann(system, x, 300.0, seed=rng))


def test_maxwell_boltzmann_respects_constraints(build):
    built = build.tip4p_waters(20)
    system, x = built.system, built.positions
    m = masses(system)
    v = maxwell_boltzmann(system, x, 300.0, seed=2)
    for k in range(system.getNumConstraints()):
        i, j, _ = system.getConstraintParameters(k)
        r = x[i] - x[j]
        assert abs(np.dot(v[i] - v[j], r)) < 1e-10 * np.linalg.norm(v[i] - v[j]) * np.linalg.norm(r)
    assert np.abs((m[:, None] * v).sum(0)).max() < 1e-10 * np.sum(m[:, None] * np.abs(v))
    assert np.all(v[3::4] == 0.0)  # the virtual sites
    dof = degrees_of_freedom(system) - 3  # 6 per rigid water, less the net momentum
    assert abs(_temperature(v, m, dof) - 300.0) < 4 * 300.0 * np.sqrt(2 / dof)


def test_a_spin_at_zero_temperature_is_an_exact_rigid_rotation(build):
    built = build.tip4p_waters(5)
    system, x = built.system, built.positions
    m = masses(system)
    omega = np.array([1.0, -2.0, 3.0])
    v = maxwell_boltzmann(system, x, 0.0, seed=1, angular_velocity=omega)
    expected = np.cross(omega, x - centre_of_mass(x, m))
    expected[m == 0] = 0.0
    np.testing.assert_allclose(v, expected, rtol=0, atol=1e-12 * np.abs(expected).max())
    np.testing.assert_allclose(angular_momentum(x, v, m, about="com"), inertia_tensor(x, m, about="com") @ omega,
                               rtol=1e-12)


def test_constrain_velocities(build):
    built = build.tip4p_waters(4)
    system, x = built.system, built.positions
    m = masses(system)
    v0 = np.random.default_rng(0).normal(size=x.shape)
    v0[3::4] = 0.0
    v = constrain_velocities(system, x, v0)
    np.testing.assert_allclose(constrain_velocities(system, x, v), v, atol=1e-10)  # a projection
    np.testing.assert_allclose((m[:, None] * v).sum(0), (m[:, None] * v0).sum(0), atol=1e-10)  # internal forces
    assert kinetic_energy(v, m) < kinetic_energy(v0, m)
    free = build.chain().system
    np.testing.assert_array_equal(constrain_velocities(free, x[:5], v0[:5]), v0[:5])  # nothing to constrain


def _energy(system, x):
    ctx = mm.Context(system, mm.VerletIntegrator(0.001), mm.Platform.getPlatformByName("Reference"))
    ctx.setPositions(x)
    state = ctx.getState(getEnergy=True, getForces=True)
    return state.getPotentialEnergy()._value, state.getForces(asNumpy=True)._value


def test_minimise_lowers_the_energy_and_keeps_constraints(build):
    built = build.chain(masses=(12.0, 14.0, 12.0, 16.0, 1.0, 12.0), constraints=[(0, 1)], seed=4)
    system, x0 = built.system, built.positions.copy()
    x0[2] += [0.03, -0.02, 0.01]  # strain a bond
    e0, f0 = _energy(system, x0)
    x = minimise(system, x0, tolerance=1.0, max_iterations=500)
    e, f = _energy(system, x)
    assert e < e0 - 1.0
    assert np.sqrt(np.mean(f ** 2)) < np.sqrt(np.mean(f0 ** 2))
    assert constraint_violation(x, system) < 1e-5  # OpenMM's default constraint tolerance


def test_equilibrate_gives_a_constrained_state(build):
    built = build.tip4p_waters(3)
    x, v = equilibrate(built.system, built.positions, 300.0, picoseconds=0.05, seed=3, step_fs=1.0,
                       platform="Reference")
    assert constraint_violation(x, built.system) < 1e-4
    assert not np.allclose(x, built.positions)
    np.testing.assert_allclose(constrain_velocities(built.system, x, v), v, atol=1e-10)
