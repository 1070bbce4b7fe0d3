"""Self-diffusion from centre-of-mass trajectories: random walks with a known D, ballistic and Brownian (Langevin)
motion, unwrapping across periodic boundaries, and the Yeh-Hummer correction by hand."""
import numpy as np
import pytest

from openmm_symprk.analysis.diffusion import (NM2_PER_PS_IN_1E5_CM2_PER_S, VISCOSITY_MPAS,
                                                      mean_squared_displacement, remove_drift, self_diffusion,
                                                      unwrap, yeh_hummer)

D_WATER = 2.5e-3  # nm^2/ps = 2.5e-5 cm^2/s


def _random_walk(D, dt, n_frames, n_mol, rng):
    steps = rng.normal(scale=np.sqrt(2 * D * dt), size=(n_frames - 1, n_mol, 3))
    return np.concatenate([np.zeros((1, n_mol, 3)), np.cumsum(steps, axis=0)]) + rng.uniform(0, 2, (n_mol, 3))


@pytest.mark.parametrize("error", ["molecules", "blocks"])
def test_random_walk_recovers_its_diffusion_coefficient(error):
    rng = np.random.default_rng(4)
    r = _random_walk(D_WATER, 0.1, 2000, 200, rng)
    fit = self_diffusion(r, 0.1, (1.0, 10.0), error=error, n_blocks=5, drift=False)
    D = D_WATER * NM2_PER_PS_IN_1E5_CM2_PER_S
    assert abs(fit.D - D) < 3 * fit.se, f"{fit} against {D}"
    assert fit.se < 0.05 * D  # resolved, not a loose bar


def test_the_standard_error_is_the_scatter_of_independent_runs():
    """Over 40 independent random walks the spread of D is the standard error the fit states (within 30%)."""
    rng = np.random.default_rng(5)
    fits = [self_diffusion(_random_walk(D_WATER, 0.1, 400, 60, rng), 0.1, (0.5, 5.0), drift=False)
            for _ in range(40)]
    D = np.array([f.D for f in fits])
    se = np.sqrt(np.mean([f.se ** 2 for f in fits]))
    assert 0.7 < D.std(ddof=1) / se < 1.3
    assert abs(D.mean() - D_WATER * 1000) < 3 * D.std(ddof=1) / np.sqrt(len(D))


def test_ballistic_motion_gives_msd_v2_t2_exactly():
    rng = np.random.default_rng(6)
    v = rng.normal(size=(30, 3))
    t = np.arange(100) * 0.01
    r = t[:, None, None] * v[None] + rng.normal(size=(30, 3))
    msd = mean_squared_displacement(r)
    np.testing.assert_allclose(msd, t[:len(msd), None] ** 2 * (v * v).sum(axis=1), rtol=1e-9, atol=1e-12)


def test_brownian_particles_diffuse_at_kt_over_m_gamma_once_past_the_ballistic_regime():
    """Langevin particles (exact Ornstein-Uhlenbeck velocities, gamma = 10/ps, kT/m = 0.025 nm^2/ps^2): the MSD
    follows 6 (kT/m gamma) [t - (1 - exp(-gamma t)) / gamma], and the fit past 5/gamma gives D = kT/(m gamma);
    a window inside the ballistic regime does not."""
    rng = np.random.default_rng(7)
    gamma, kt_m, dt, n, nm = 10.0, 0.025, 0.005, 6000, 100
    D = kt_m / gamma
    c = np.exp(-gamma * dt)
    v = np.empty((n, nm, 3))
    v[0] = rng.normal(scale=np.sqrt(kt_m), size=(nm, 3))
    noise = rng.normal(scale=np.sqrt(kt_m * (1 - c * c)), size=(n, nm, 3))
    for k in range(1, n):
        v[k] = c * v[k - 1] + noise[k]
    r = np.concatenate([np.zeros((1, nm, 3)), np.cumsum(0.5 * (v[1:] + v[:-1]) * dt, axis=0)])
    fit = self_diffusion(r, dt, (1.0, 5.0), drift=False)
    assert abs(fit.D - D * 1000) < 3 * fit.se and fit.se < 0.05 * D * 1000
    t = fit.lag_ps[:200]
    theory = 6 * D * (t - (1 - np.exp(-gamma * t)) / gamma)
    np.testing.assert_allclose(fit.msd[1:200], theory[1:], rtol=0.05)
    ballistic = self_diffusion(r, dt, (0.01, 0.05), drift=False)
    assert ballistic.D < 0.5 * D * 1000


def test_a_translating_whole_is_taken_out_and_independent_walkers_lose_one_over_n():
    """Random walkers (D) all carried at V = 0.05 nm/ps: with the drift taken out, D (1 - 1/n) as the
    common centre's own diffusion goes with it; without, the V^2 t^2 term more than doubles the slope."""
    rng = np.random.default_rng(9)
    n = 50
    walk = _random_walk(D_WATER, 0.1, 2000, n, rng)
    moving = walk + (np.arange(2000) * 0.1)[:, None, None] * np.array([0.05, 0.0, 0.0])
    kept = self_diffusion(moving, 0.1, (1.0, 10.0))
    assert abs(kept.D - D_WATER * 1000 * (1 - 1 / n)) < 3 * kept.se
    np.testing.assert_allclose(remove_drift(moving), remove_drift(walk), atol=1e-9)
    assert self_diffusion(moving, 0.1, (1.0, 10.0), drift=False).D > 2 * D_WATER * 1000
    # weights: a molecule at rest, heavy enough to carry the centre, anchors it: nothing is taken out
    anchored = moving.copy()
    anchored[:, 0] = anchored[0, 0]
    np.testing.assert_allclose(remove_drift(anchored, np.r_[1e12, np.ones(n - 1)]), anchored, atol=1e-9)


def test_unwrapping_a_particle_crossing_the_box_several_times():
    box = np.array([2.0, 3.0, 2.5])
    t = np.arange(400) * 0.05
    true = np.stack([0.3 + 1.1 * t, 2.9 - 0.7 * t, 1.0 + 0.2 * np.sin(t)], axis=1)[:, None, :]  # 11 crossings in x
    wrapped = true - box * np.floor(true / box)
    assert np.abs(np.diff(wrapped[:, 0, 0])).max() > 1.5  # it does jump
    np.testing.assert_allclose(unwrap(wrapped, box), true, atol=1e-12)


def test_unwrapping_restores_wrapped_random_walks_and_their_diffusion():
    rng = np.random.default_rng(8)
    r = _random_walk(0.05, 0.1, 500, 20, rng)  # wanders several boxes of 1.5 nm
    box = np.full(3, 1.5)
    wrapped = r - box * np.floor(r / box)
    back = unwrap(wrapped, box)
    np.testing.assert_allclose(back - back[0], r - r[0], atol=1e-10)
    fits = [self_diffusion(r, 0.1, (1, 10), drift=False).D for r in (wrapped, back)]
    assert fits[0] < 0.5 * fits[1]


def test_unwrapping_refuses_steps_too_long_to_tell_the_image():
    r = np.array([[[0.1, 0.1, 0.1]], [[0.95, 0.1, 0.1]]])
    with pytest.raises(ValueError, match="store frames more often"):
        unwrap(r, [2.0, 2.0, 2.0])


def test_yeh_hummer_by_hand():
    """k_B T xi / (6 pi eta L) at 300 K, eta = 0.729 mPa s, L = 1.863 nm:
    1.380649e-23 * 300 * 2.837297 / (6 pi * 0.729e-3 * 1.863e-9) = 4.5906e-10 m^2/s = 0.45906e-5 cm^2/s."""
    assert yeh_hummer(1.863, 300.0, VISCOSITY_MPAS["spce"]) == pytest.approx(0.45906, rel=1e-4)
    # inversely proportional to the box edge and the viscosity
    assert yeh_hummer(3.726, 300.0, 0.729) == pytest.approx(0.5 * yeh_hummer(1.863, 300.0, 0.729), rel=1e-12)


def test_bad_input_is_named():
    r = np.zeros((50, 3, 3))
    with pytest.raises(ValueError, match="fit window"):
        self_diffusion(r, 0.1, (1.0, 100.0))
    with pytest.raises(ValueError, match="dt_ps"):
        self_diffusion(r, 0.0, (1.0, 2.0))
    with pytest.raises(ValueError, match="viscosity_mpas"):
        yeh_hummer(2.0, 300.0, 0.0)
    with pytest.raises(ValueError, match="box"):
        unwrap(r, [1.0, 1.0])
