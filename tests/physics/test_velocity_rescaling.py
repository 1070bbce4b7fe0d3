"""physics.velocity_rescaling: the Bussi-Donadio-Parrinello resampling is the exact kinetic-energy law of an
Ornstein-Uhlenbeck velocity vector, samples the canonical distribution, and keeps what it must keep."""
import math

import numpy as np
import pytest
from scipy import stats

from openmm_symprk.physics import angular_momentum, linear_momentum
from openmm_symprk.physics.velocity_rescaling import (draw_noise, kept_velocities, relaxation_factor, resample,
                                                      rescaling_factor, thermostat_dof)


@pytest.mark.parametrize("c", [0.0, 0.3, 0.97])
def test_resampling_is_the_ou_vector_kinetic_energy_exactly(c):
    """With the noise of an explicit OU step v' = sqrt(c) v + sqrt(1-c) sigma xi split into its component along
    v (R1) and the rest (S), the formula gives |v'|^2/2 to round-off and the sign of v'.v."""
    rng = np.random.default_rng(3)
    dof, kT = 40, 2.5
    target = 0.5 * dof * kT
    for _ in range(50):
        v = rng.normal(scale=rng.uniform(0.2, 3.0), size=dof)
        xi = rng.normal(size=dof)
        new_v = math.sqrt(c) * v + math.sqrt((1 - c) * kT) * xi
        r1 = xi @ v / np.linalg.norm(v)
        chi2 = xi @ xi - r1 * r1
        alpha, new = rescaling_factor(0.5 * v @ v, target, dof, c, r1, chi2)
        assert new == pytest.approx(0.5 * new_v @ new_v, rel=1e-12)
        assert np.sign(alpha) == np.sign(new_v @ v)


def test_chain_samples_the_canonical_kinetic_energy():
    """Repeated events from a cold start: K is Gamma(N_f/2, kT) (mean N_f kT/2, variance N_f (kT)^2/2;
    Kolmogorov-Smirnov against the exact law on thinned samples)."""
    rng = np.random.default_rng(11)
    dof, kT, c = 30, 2.494, math.exp(-0.5)
    target = 0.5 * dof * kT
    k, chain = 1e-3, []
    for _ in range(40000):
        k = resample(k, target, dof, c, rng).new_kinetic
        chain.append(k)
    chain = np.array(chain[200:])
    thin = chain[::10]  # correlation time ~ 1/(1-c) events; thinning makes the samples nearly independent
    se_mean = thin.std() / math.sqrt(len(thin))
    assert abs(thin.mean() - target) < 3 * se_mean
    var_expected = 0.5 * dof * kT ** 2
    se_var = var_expected * math.sqrt(2.0 / len(thin)) * 1.6  # Gamma kurtosis widens the variance's error
    assert abs(thin.var() - var_expected) < 3 * se_var
    assert stats.kstest(thin, stats.gamma(a=0.5 * dof, scale=kT).cdf).pvalue > 1e-3


def test_strong_coupling_draws_a_fresh_canonical_energy():
    """c = 0: K' no longer depends on K and is exactly (kT/2) chi^2_{N_f}."""
    rng = np.random.default_rng(5)
    dof, kT = 12, 1.0
    samples = [resample(50.0, 0.5 * dof * kT, dof, 0.0, rng).new_kinetic for _ in range(4000)]
    assert stats.kstest(samples, stats.gamma(a=0.5 * dof, scale=kT).cdf).pvalue > 1e-3


def test_no_coupling_changes_nothing():
    assert rescaling_factor(3.0, 10.0, 8, 1.0, 0.7, 4.0) == (1.0, 3.0)
    assert rescaling_factor(0.0, 10.0, 8, 0.5, 0.7, 4.0) == (1.0, 0.0)


def test_noise_and_factor_arguments():
    rng = np.random.default_rng(0)
    chi = [draw_noise(rng, 9)[1] for _ in range(20000)]
    assert abs(np.mean(chi) - 8) < 3 * math.sqrt(2 * 8 / len(chi))
    assert draw_noise(rng, 1)[1] == 0.0
    with pytest.raises(ValueError, match="at least one degree of freedom"):
        draw_noise(rng, 0)
    assert relaxation_factor(0.002, 0.1) == pytest.approx(math.exp(-0.02))
    with pytest.raises(ValueError, match="collision_time > 0"):
        relaxation_factor(0.002, 0.0)


def test_degrees_of_freedom():
    assert thermostat_dof(10, 0, isolated=False) == 27
    assert thermostat_dof(10, 0, isolated=True) == 24
    assert thermostat_dof(9, 9, isolated=True) == 12  # three rigid waters: 3 x 6 - 6


def test_peculiar_velocities_carry_no_momentum():
    rng = np.random.default_rng(8)
    x, v, m = rng.normal(size=(9, 3)), rng.normal(size=(9, 3)), rng.uniform(1, 16, 9)
    pec = v - kept_velocities(x, v, m, keep_rotation=True)
    assert np.allclose(linear_momentum(pec, m), 0, atol=1e-12)
    assert np.allclose(angular_momentum(x, pec, m, about="com"), 0, atol=1e-12)
    pec_t = v - kept_velocities(x, v, m, keep_rotation=False)
    assert np.allclose(linear_momentum(pec_t, m), 0, atol=1e-12)
    # Scaling the peculiar part keeps P and L exactly as they were.
    scaled = kept_velocities(x, v, m, keep_rotation=True) + 0.37 * pec
    assert np.allclose(linear_momentum(scaled, m), linear_momentum(v, m), atol=1e-12)
    assert np.allclose(angular_momentum(x, scaled, m, about="com"), angular_momentum(x, v, m, about="com"),
                       atol=1e-12)


def test_rigid_motion_is_all_kept():
    rng = np.random.default_rng(9)
    x, m = rng.normal(size=(6, 3)), rng.uniform(1, 16, 6)
    v = np.array([0.3, -0.2, 0.1]) + np.cross([0.5, 1.0, -2.0], x - (m[:, None] * x).sum(0) / m.sum())
    assert np.allclose(kept_velocities(x, v, m, keep_rotation=True), v, atol=1e-12)


def test_round_off_peculiar_energy_is_not_scaled():
    """K_pec at most 1e-10 of the total kinetic energy (a rigid translation's round-off): factor 1, nothing drawn
    into the kept motion; just above it the event acts."""
    from openmm_symprk.physics.velocity_rescaling import ROUNDOFF, no_peculiar_motion

    total = 250.0
    assert no_peculiar_motion(0.0, 0.0) and no_peculiar_motion(ROUNDOFF * total, total)
    assert rescaling_factor(ROUNDOFF * total, 10.0, 8, 0.5, 0.7, 4.0, total_kinetic=total) == (1.0, ROUNDOFF * total)
    alpha, _ = rescaling_factor(2 * ROUNDOFF * total, 10.0, 8, 0.5, 0.7, 4.0, total_kinetic=total)
    assert alpha > 1e3  # the factor that would amplify round-off, where the peculiar energy is not round-off


def test_linear_isolated_systems_have_two_rotations():
    assert thermostat_dof(2, 0, True) == 1  # a diatomic: its vibration
    assert thermostat_dof(2, 1, True) == 0  # a rigid diatomic: nothing left
    assert thermostat_dof(1, 0, True) == 0
    assert thermostat_dof(3, 0, True) == 3  # three particles: three rotations (the System does not say linear)
    assert thermostat_dof(2, 0, False) == 3
