"""Translational and rotational kinetic temperatures of molecules: cases with a known answer."""
import numpy as np
import pytest
from scipy.spatial.transform import Rotation

from openmm_symprk.physics.temperature import R_KJ, kinetic_temperatures, molecule_kinetics

WATER = np.array([[0.0, 0.0, 0.0], [0.09572, 0.0, 0.0], [-0.0239987, 0.0926627, 0.0]])
MASSES = np.array([15.9994, 1.008, 1.008])


def _waters(n, t_trans, t_rot, seed=3, exact=True):
    """n rigid waters: centre-of-mass velocities at t_trans (zero total momentum), rigid rotations at t_rot
    (each principal axis at kT/2), then, with ``exact``, rescaled to exactly those temperatures."""
    rng = np.random.default_rng(seed)
    com0 = (MASSES[:, None] * WATER).sum(0) / MASSES.sum()
    M = MASSES.sum()
    xs, Vs, Ws = [], [], []
    for k in range(n):
        R = Rotation.random(random_state=rng).as_matrix()
        body = (WATER - com0) @ R.T
        xs.append(body + rng.uniform(0, 5, 3))
        I = np.eye(3) * (MASSES * (body ** 2).sum(1)).sum() - np.einsum("i,ij,ik->jk", MASSES, body, body)
        moments, axes = np.linalg.eigh(I)
        Ws.append(axes @ (rng.normal(size=3) * np.sqrt(R_KJ * t_rot / moments)))
        Vs.append(rng.normal(size=3) * np.sqrt(R_KJ * t_trans / M))
    V = np.array(Vs)
    V -= V.mean(0)  # zero total momentum (all molecules have the same mass)
    W = np.array(Ws)
    x = np.concatenate(xs)
    if exact:
        ktr = 0.5 * M * (V * V).sum()
        V *= np.sqrt(0.5 * (3 * n - 3) * R_KJ * t_trans / ktr)
        krot = sum(0.5 * (MASSES[:, None] * np.cross(W[k], x[3*k:3*k+3] - (MASSES[:, None] * x[3*k:3*k+3]).sum(0) / M)
                                                      ** 2).sum() for k in range(n))
        W *= np.sqrt(0.5 * 3 * n * R_KJ * t_rot / krot)
    v = np.concatenate([V[k] + np.cross(W[k], x[3*k:3*k+3] - (MASSES[:, None] * x[3*k:3*k+3]).sum(0) / M)
                        for k in range(n)])
    return x, v, np.tile(MASSES, n), [list(range(3 * k, 3 * k + 3)) for k in range(n)]


def test_prescribed_translational_and_rotational_temperatures_are_recovered_exactly():
    x, v, m, mols = _waters(50, 280.0, 320.0)
    t = kinetic_temperatures(x, v, m, mols, constraints=3 * 50)
    assert t.translational == pytest.approx(280.0, rel=1e-12) and t.rotational == pytest.approx(320.0, rel=1e-12)
    assert t.difference == pytest.approx(40.0, rel=1e-10)
    assert (t.translational_dof, t.rotational_dof, t.internal_dof) == (147, 150, 0) and np.isnan(t.internal)


def test_a_uniform_drift_of_the_whole_set_is_not_temperature():
    """With the total momentum fixed, the motion of the centre of mass of all molecules is not thermal: the
    prescribed temperatures come back in any uniformly moving frame; counted as translation without
    ``momentum_fixed`` (3 N DOF), the drift's kinetic energy shows up exactly."""
    x, v, m, mols = _waters(50, 280.0, 320.0)
    boost = np.array([0.3, -0.2, 0.5])  # nm/ps, ~ a thermal centre-of-mass speed of a small box
    t = kinetic_temperatures(x, v + boost, m, mols, constraints=3 * 50)
    assert t.translational == pytest.approx(280.0, rel=1e-12) and t.rotational == pytest.approx(320.0, rel=1e-12)
    free = kinetic_temperatures(x, v + boost, m, mols, momentum_fixed=False, constraints=3 * 50)
    k_drift = 0.5 * m.sum() * float(boost @ boost)
    assert free.translational_dof == 150
    assert free.translational == pytest.approx((280.0 * 147 * R_KJ / 2 + k_drift) * 2 / (R_KJ * 150), rel=1e-12)


def test_random_draws_equipartition_statistically():
    x, v, m, mols = _waters(3000, 300.0, 300.0, seed=5, exact=False)
    t = kinetic_temperatures(x, v, m, mols, constraints=3 * 3000)
    sigma = 300.0 * np.sqrt(2 / 9000)  # relative spread sqrt(2/f) of a kinetic temperature with f DOF
    assert abs(t.translational - 300.0) < 4 * sigma and abs(t.rotational - 300.0) < 4 * sigma


def test_internal_motion_is_separated():
    """A symmetric stretch (no net momentum, no angular momentum about the centre of mass) is internal only."""
    x, v, m, mols = _waters(20, 300.0, 300.0)
    base = molecule_kinetics(x, v, m, mols)
    stretch = np.zeros_like(v)
    for k in range(20):
        o, h1, h2 = x[3*k], x[3*k+1], x[3*k+2]
        u1, u2 = (h1 - o) / np.linalg.norm(h1 - o), (h2 - o) / np.linalg.norm(h2 - o)
        stretch[3*k+1], stretch[3*k+2] = 0.5 * u1, 0.5 * u2
        stretch[3*k] = -(MASSES[1] * stretch[3*k+1] + MASSES[2] * stretch[3*k+2]) / MASSES[0]
    mk = molecule_kinetics(x, v + stretch, m, mols)
    # the stretch has zero momentum and, being symmetric in a plane through the centre of mass, zero torque
    np.testing.assert_allclose(mk.translational, base.translational, rtol=1e-12)
    np.testing.assert_allclose(mk.rotational, base.rotational, rtol=1e-9, atol=1e-12)
    t = kinetic_temperatures(x, v + stretch, m, mols, constraints=0)
    assert t.internal_dof == 60 and t.internal > 0


def test_linear_molecules_and_atoms_count_their_rotational_dof():
    x = np.array([[0.0, 0, 0], [0.1, 0, 0], [1.0, 1, 1]])
    v = np.array([[0.0, 1, 0], [0.0, -1, 0], [1.0, 0, 0]])
    m = np.array([1.0, 1.0, 4.0])
    mk = molecule_kinetics(x, v, m, [[0, 1], [2]])
    assert list(mk.rotational_dof) == [2, 0]
    assert mk.rotational[0] == pytest.approx(1.0) and mk.translational[1] == pytest.approx(2.0)
