"""Reorientation: rotational diffusion on the sphere with a known D_r gives C_l(t) = exp(-l(l+1) D_r t), so
tau_1 = 1/(2 D_r) and tau_2 = 1/(6 D_r); the correlation time's integral-plus-tail by hand; the vectors."""
import numpy as np
import pytest

from openmm_symprk.analysis.reorientation import (atom_vectors, bisector_vectors, correlation_time,
                                                          dipole_vectors, legendre_correlation,
                                                          reorientation_time)


def _rotate(u, theta):
    """Rodrigues: rotate the vectors u (n, 3) by the rotation vectors theta (n, 3)."""
    angle = np.linalg.norm(theta, axis=1, keepdims=True)
    k = theta / np.where(angle > 0, angle, 1.0)
    return (u * np.cos(angle) + np.cross(k, u) * np.sin(angle)
            + k * (k * u).sum(axis=1, keepdims=True) * (1 - np.cos(angle)))


def _rotational_diffusion(Dr, dt, n_frames, n_mol, rng):
    """Isotropic rotational Brownian motion: each step a rotation by a Gaussian rotation vector of variance
    2 D_r dt per component (its decay rate is exact to O(D_r dt): 0.1% at D_r dt = 0.005, used here)."""
    u = rng.normal(size=(n_mol, 3))
    u /= np.linalg.norm(u, axis=1, keepdims=True)
    out = np.empty((n_frames, n_mol, 3))
    out[0] = u
    for k in range(1, n_frames):
        out[k] = u = _rotate(u, rng.normal(scale=np.sqrt(2 * Dr * dt), size=(n_mol, 3)))
    return out


@pytest.fixture(scope="module")
def diffusing():
    return _rotational_diffusion(0.5, 0.01, 4000, 200, np.random.default_rng(11))


@pytest.mark.parametrize("order, tau", [(1, 1.0), (2, 1.0 / 3.0)])
def test_rotational_diffusion_gives_the_known_correlation_times(diffusing, order, tau):
    c, t = reorientation_time(diffusing, order, 0.01)
    assert abs(t.tau - tau) < 3 * t.se, f"tau_{order} = {t} ps, expected {tau:.4f}"
    assert t.se < 0.05 * tau
    assert abs(t.tau_exp - tau) < 0.15 * tau  # the tail's time constant is the same exponential (4% scatter)
    lags = np.arange(len(c)) * 0.01
    near = lags < 2 * tau
    np.testing.assert_allclose(c[near], np.exp(-lags[near] / tau), atol=0.02)


def test_the_jackknife_error_is_the_scatter_of_independent_runs():
    """Over 24 independent sets of 100 molecules, the spread of tau_1 is the standard error stated (within 35%)."""
    rng = np.random.default_rng(16)
    fits = [reorientation_time(_rotational_diffusion(0.5, 0.01, 1500, 100, rng), 1, 0.01)[1] for _ in range(24)]
    tau = np.array([f.tau for f in fits])
    se = np.sqrt(np.mean([f.se ** 2 for f in fits]))
    assert 0.65 < tau.std(ddof=1) / se < 1.35, (tau.std(ddof=1), se)
    assert abs(tau.mean() - 1.0) < 3 * tau.std(ddof=1) / np.sqrt(len(tau))


def test_legendre_correlations_at_lag_zero_are_one(diffusing):
    for order in (1, 2):
        np.testing.assert_allclose(legendre_correlation(diffusing[:100], order)[0], 1.0, atol=1e-12)


def test_p2_equals_its_definition_by_the_double_loop():
    u = _rotational_diffusion(2.0, 0.01, 40, 3, np.random.default_rng(12))
    c = legendre_correlation(u, 2, max_lag=39)
    for m in (1, 5, 39):
        x = (u[:40 - m] * u[m:]).sum(axis=2)
        np.testing.assert_allclose(c[m], (1.5 * x * x - 0.5).mean(axis=0), atol=1e-12)


def test_correlation_time_is_integral_plus_exponential_tail():
    """A fast drop to 0.8 then exp(-t/2): tau = integral of the measured part + the exact tail; the tail
    alone carries C(t_cut) * 2 ps."""
    dt = 0.01
    t = np.arange(1000) * dt
    c = np.where(t < 0.05, 1 - 4 * t, 0.8 * np.exp(-(t - 0.05) / 2.0))
    exact = 0.05 * (1 + 0.8) / 2 + 0.8 * 2.0
    r = correlation_time(c, dt)
    assert r.tau == pytest.approx(exact, rel=1e-4)
    assert r.tau_exp == pytest.approx(2.0, rel=1e-6)
    assert r.tail == pytest.approx(c[int(round(r.t_cut / dt))] * 2.0, rel=1e-6)


def test_a_correlation_too_short_to_fit_is_refused():
    c = np.exp(-np.arange(50) * 0.01 / 10.0)  # never below 0.5
    with pytest.raises(ValueError, match="run longer"):
        correlation_time(c, 0.01)


def _water(n, rng):
    """Rigid water-like molecules (O, H, H) at random orientations: positions (1, 3n, 3)."""
    body = np.array([[0.0, 0.0, 0.0], [0.0816, 0.0, 0.0577], [-0.0816, 0.0, 0.0577]])
    q, _ = np.linalg.qr(rng.normal(size=(n, 3, 3)))
    x = np.einsum("nij,kj->nki", q, body) + rng.uniform(0, 2, (n, 1, 3))
    return x.reshape(1, -1, 3), [[3 * i, 3 * i + 1, 3 * i + 2] for i in range(n)]


def test_water_dipole_lies_along_the_bisector_and_is_perpendicular_to_hh():
    x, mols = _water(10, np.random.default_rng(13))
    charges = np.tile([-0.8476, 0.4238, 0.4238], 10)
    mu = dipole_vectors(x, mols, charges)
    np.testing.assert_allclose(mu, bisector_vectors(x, mols), atol=1e-12)
    np.testing.assert_allclose((mu * atom_vectors(x, mols, 1, 2)).sum(axis=2), 0.0, atol=1e-12)


def test_molecules_split_by_the_box_are_made_whole():
    x, mols = _water(5, np.random.default_rng(14))
    box = np.array([2.0, 2.0, 2.0])
    split = x.copy()
    split[0, 1] += box * [1, 0, -1]  # one H of the first molecule one image away
    np.testing.assert_allclose(atom_vectors(split, mols, 1, 2, box=box), atom_vectors(x, mols, 1, 2), atol=1e-12)


def test_charged_molecules_have_no_dipole_vector():
    x, mols = _water(2, np.random.default_rng(15))
    with pytest.raises(ValueError, match="net charge"):
        dipole_vectors(x, mols, np.tile([-0.8, 0.5, 0.5], 2))
