"""openmm_symprk.physics: momenta about a stated point, checked against exact cases (pure numpy)."""
import numpy as np
import pytest

from openmm_symprk.physics import angular_momentum, centre_of_mass, inertia_tensor, kinetic_energy, linear_momentum


def _cloud(seed=4, n=7):
    rng = np.random.default_rng(seed)
    return rng.normal(size=(n, 3)), rng.uniform(1, 16, n)


def test_rigid_rotation_gives_inertia_times_omega():
    """A rigid rotation v = w x (r - c) about the centre of mass: L = I w exactly, P = 0."""
    x, m = _cloud()
    w = np.array([0.3, -1.0, 2.0])
    v = np.cross(w, x - centre_of_mass(x, m))
    assert np.allclose(angular_momentum(x, v, m, about="com"), inertia_tensor(x, m, about="com") @ w,
                       rtol=1e-13, atol=1e-13)
    assert np.allclose(linear_momentum(v, m), 0, atol=1e-13)


def test_points_are_stated_and_related():
    """L_origin = L_com + M c x V, and an explicit point equals the named one."""
    x, m = _cloud(5)
    v = np.random.default_rng(6).normal(size=x.shape)
    c, M = centre_of_mass(x, m), m.sum()
    V = linear_momentum(v, m) / M
    assert np.allclose(angular_momentum(x, v, m, about="origin"),
                       angular_momentum(x, v, m, about="com") + M * np.cross(c, V), rtol=1e-12, atol=1e-12)
    assert np.array_equal(angular_momentum(x, v, m, about=c), angular_momentum(x, v, m, about="com"))
    assert kinetic_energy(v, m) == pytest.approx(0.5 * np.sum(m[:, None] * v * v), rel=1e-15)


def test_about_must_be_stated_and_valid():
    x, m = _cloud()
    with pytest.raises(TypeError):
        angular_momentum(x, x, m)  # no default point: "com" and "origin" differ
    with pytest.raises(ValueError, match="'com', 'origin' or a point"):
        angular_momentum(x, x, m, about="centre")
    with pytest.raises(ValueError, match="no mass"):
        centre_of_mass(x, np.zeros(len(m)))


def test_massless_particles_drop_out():
    x, m = _cloud()
    v = np.ones_like(x)
    m2 = np.append(m, 0.0)
    x2, v2 = np.vstack([x, [[9.0, 9.0, 9.0]]]), np.vstack([v, [[5.0, 5.0, 5.0]]])
    assert np.allclose(angular_momentum(x2, v2, m2, about="com"), angular_momentum(x, v, m, about="com"))
