"""Angular velocity of molecules and its autocorrelation: a rigid water rotating freely about a principal axis
(constant omega, C(t) = 1), a general rigid rotation recovered exactly, known synthetic omega(t) series."""
import numpy as np
import pytest

from openmm_symprk.analysis.angular import (acf_summary, angular_velocities, angular_velocity_acf,
                                                   omega_correlation)

BODY = np.array([[0.0, 0.0, -0.0065], [0.0816, 0.0, 0.0512], [-0.0816, 0.0, 0.0512]])  # O, H, H about ~com, nm
MASS = np.array([15.9994, 1.008, 1.008])


def _rotation(axis, angle):
    axis = np.asarray(axis, float) / np.linalg.norm(axis)
    k = np.array([[0, -axis[2], axis[1]], [axis[2], 0, -axis[0]], [-axis[1], axis[0], 0]])
    return np.eye(3) + np.sin(angle) * k + (1 - np.cos(angle)) * k @ k


def _spinning(omega, V, t, start=np.eye(3), origin=(1.0, 2.0, 3.0)):
    """A rigid water turning at constant ``omega`` (space frame, rad/ps) while its centre moves at V: x, v."""
    com = (MASS[:, None] * BODY).sum(0) / MASS.sum()
    body = BODY - com
    x, v = [], []
    for tk in t:
        R = _rotation(omega, np.linalg.norm(omega) * tk) @ start if np.any(omega) else start
        r = body @ R.T
        x.append(np.asarray(origin) + V * tk + r)
        v.append(V + np.cross(omega, r))
    return np.array(x), np.array(v)


def test_water_principal_axes_are_hh_bisector_normal():
    """Ascending moments: the H-H direction, the symmetry axis, the normal (what the body frame documents)."""
    t = np.array([0.0])
    for axis, expected in ((0, [1, 0, 0]), (1, [0, 1, 0]), (2, [0, 0, 1])):
        omega = np.zeros(3)
        omega[[0, 2, 1][axis]] = 3.0  # body x = H-H, z = bisector, y = normal
        x, v = _spinning(omega, np.zeros(3), t)
        w = angular_velocities(x, v, MASS, [[0, 1, 2]], frame="body")[0, 0]
        np.testing.assert_allclose(np.abs(w), 3.0 * np.array(expected), atol=1e-10)


@pytest.mark.parametrize("frame", ["space", "body"])
def test_free_rotation_about_a_principal_axis_has_constant_omega_and_acf_one(frame):
    t = np.arange(300) * 0.01
    x, v = _spinning(np.array([0.0, 0.0, 25.0]), np.array([0.3, -0.1, 0.2]), t)  # about the symmetry axis
    w = angular_velocities(x, v, MASS, [[0, 1, 2]], frame=frame)
    np.testing.assert_allclose(w, np.broadcast_to(w[0], w.shape), atol=1e-9)
    assert np.linalg.norm(w[0]) == pytest.approx(25.0, rel=1e-12)
    np.testing.assert_allclose(angular_velocity_acf(w), 1.0, atol=1e-12)


def test_any_rigid_rotation_is_recovered_in_space_and_body_frames():
    rng = np.random.default_rng(21)
    omega = rng.normal(size=3) * 10
    start = _rotation(rng.normal(size=3), 1.3)
    x, v = _spinning(omega, rng.normal(size=3), np.array([0.0, 0.07]), start=start)
    w = angular_velocities(x, v, MASS, [[0, 1, 2]])
    np.testing.assert_allclose(w[0, 0], omega, rtol=1e-10)
    wb = angular_velocities(x, v, MASS, [[0, 1, 2]], frame="body")
    np.testing.assert_allclose(np.linalg.norm(wb, axis=2), np.linalg.norm(omega), rtol=1e-10)
    # body components at t = 0: omega in the start orientation's axes (H-H, bisector, normal = x, z, -y or y)
    body = start.T @ omega
    np.testing.assert_allclose(np.abs(wb[0, 0]), np.abs(body[[0, 2, 1]]), rtol=1e-10)


def test_two_molecules_of_a_trajectory_are_kept_apart():
    t = np.arange(5) * 0.01
    x1, v1 = _spinning(np.array([0.0, 0.0, 5.0]), np.zeros(3), t)
    x2, v2 = _spinning(np.array([7.0, 0.0, 0.0]), np.zeros(3), t, origin=(3.0, 3.0, 3.0))
    w = angular_velocities(np.concatenate([x1, x2], 1), np.concatenate([v1, v2], 1), np.tile(MASS, 2),
                           [[0, 1, 2], [3, 4, 5]])
    np.testing.assert_allclose(w[:, 0], [[0, 0, 5.0]] * 5, atol=1e-9)
    np.testing.assert_allclose(w[:, 1], [[7.0, 0, 0]] * 5, atol=1e-9)


def test_a_librating_omega_gives_a_cosine_acf_with_its_first_minimum_at_half_a_period():
    """omega(t) = a cos(W t + phi) along random fixed axes, random phases over 400 molecules: C(t) = cos(W t),
    zero at pi/(2W), first minimum -1 at pi/W, integral sin(W t_max)/W."""
    rng = np.random.default_rng(22)
    W, dt, n = 20.0, 0.005, 4000
    t = np.arange(n) * dt
    axes = rng.normal(size=(400, 3))
    axes /= np.linalg.norm(axes, axis=1, keepdims=True)
    omega = np.cos(W * t[:, None] + rng.uniform(0, 2 * np.pi, 400))[..., None] * axes * 30.0
    c = angular_velocity_acf(omega, max_lag=400)
    lags = np.arange(401) * dt
    np.testing.assert_allclose(c, np.cos(W * lags), atol=0.02)
    s = acf_summary(c, dt)
    assert s.t_zero == pytest.approx(np.pi / (2 * W), abs=dt / 5)
    assert s.t_min == pytest.approx(np.pi / W, abs=dt)
    assert s.c_min == pytest.approx(-1.0, abs=0.02)
    assert s.integral == pytest.approx(np.sin(W * 2.0) / W, abs=0.01)
    assert s.t_max == pytest.approx(2.0)


def test_an_ornstein_uhlenbeck_omega_has_exponential_acf_and_integral_tau():
    rng = np.random.default_rng(23)
    tau, dt, n, m = 0.1, 0.01, 5000, 100
    a = np.exp(-dt / tau)
    w = np.empty((n, m, 3))
    w[0] = rng.normal(size=(m, 3))
    for k in range(1, n):
        w[k] = a * w[k - 1] + np.sqrt(1 - a * a) * rng.normal(size=(m, 3))
    c = angular_velocity_acf(w, max_lag=100)
    np.testing.assert_allclose(c[:50], np.exp(-np.arange(50) * dt / tau), atol=0.01)
    s = acf_summary(c, dt)
    assert s.integral == pytest.approx(tau, rel=0.05)


def test_summary_errors_are_the_scatter_of_independent_sets():
    """Damped librations omega(t) = AR(2) noise (a random phase per molecule): over 20 independent sets of 60
    molecules the spread of the first minimum and of the integral is the jackknife error stated (within 40%),
    and the curve agrees with the angular_velocity_acf of the same data."""
    rng = np.random.default_rng(26)
    r, theta = np.exp(-0.02), 2 * np.pi / 40  # damped oscillation: period 40 frames, decay 50 frames

    def series(n, m):
        w = np.zeros((n + 200, m, 3))
        e = rng.normal(size=w.shape)
        for k in range(2, n + 200):
            w[k] = 2 * r * np.cos(theta) * w[k - 1] - r * r * w[k - 2] + e[k]
        return w[200:]

    sets = [omega_correlation(series(1000, 60), 0.001, max_lag=100) for _ in range(20)]
    for field in ("c_min", "integral", "t_zero"):
        values = np.array([getattr(s, field) for _, s in sets])
        se = np.sqrt(np.mean([getattr(s, field + "_se") ** 2 for _, s in sets]))
        assert 0.6 < values.std(ddof=1) / se < 1.4, (field, values.std(ddof=1), se)
    w = series(300, 10)
    np.testing.assert_allclose(omega_correlation(w, 0.001, max_lag=50)[0], angular_velocity_acf(w, max_lag=50),
                               atol=1e-12)


def test_components_are_normalised_each():
    w = np.random.default_rng(24).normal(size=(200, 10, 3)) * [1.0, 5.0, 0.1]
    c = angular_velocity_acf(w, components=True)
    np.testing.assert_allclose(c[0], 1.0)
    assert np.abs(c[5:]).max() < 0.2


def test_a_symmetric_top_has_no_body_frame_and_bad_frames_are_named():
    x = np.array([[[0, 0, 0], [0.1, 0, 0], [-0.1, 0, 0]]], float)  # linear
    v = np.array([[[0, 0, 0], [0.1, 0.2, 0], [-0.1, -0.2, 0]]], float)
    w = angular_velocities(x, v, [1.0, 1.0, 1.0], [[0, 1, 2]])  # space frame: omega normal to the axis
    np.testing.assert_allclose(w[0, 0], [0, 0, 2.0], atol=1e-12)
    with pytest.raises(ValueError, match="frame='space'"):
        angular_velocities(x, np.zeros_like(x), [1.0, 1.0, 1.0], [[0, 1, 2]], frame="body")
    with pytest.raises(ValueError, match="'space' or 'body'"):
        angular_velocities(x, np.zeros_like(x), [1.0, 1.0, 1.0], [[0, 1, 2]], frame="lab")


def test_rotational_energy_from_omega_is_the_temperature_modules():
    """1/2 omega . I omega summed over molecules equals physics.temperature's rotational kinetic energy
    (one definition of the molecule's frame behind both), for random rigid-water velocities."""
    from openmm_symprk.physics.temperature import molecule_kinetics
    from openmm_symprk.analysis.molecules import trajectory_frames

    rng = np.random.default_rng(25)
    xs, vs = [], []
    for _ in range(6):
        x, v = _spinning(rng.normal(size=3) * 8, rng.normal(size=3), np.array([0.0]),
                         start=_rotation(rng.normal(size=3), rng.uniform(0, 3)), origin=rng.uniform(0, 2, 3))
        xs.append(x)
        vs.append(v)
    x, v, m = np.concatenate(xs, 1), np.concatenate(vs, 1), np.tile(MASS, 6)
    mols = [[3 * i, 3 * i + 1, 3 * i + 2] for i in range(6)]
    w = angular_velocities(x, v, m, mols)[0]
    inertia = trajectory_frames(x, v, m, mols).inertia[0]
    k_rot = 0.5 * np.einsum("ni,nij,nj->n", w, inertia, w)
    np.testing.assert_allclose(k_rot, molecule_kinetics(x[0], v[0], m, mols).rotational, rtol=1e-10)


# -- grid-free features: the same curve read on a fine and a coarse grid ----------------------------------------------
def _libration_acf(t_fs):
    """A normalised angular-velocity ACF shaped like rigid water's (first zero near 15 fs, first minimum near -0.47
    at 27 fs): a damped cosine plus a slow positive tail."""
    t = np.asarray(t_fs, dtype=float)
    return 0.95 * np.exp(-t / 45.0) * np.cos(np.pi * t / 28.8) + 0.05 * np.exp(-t / 300.0)


@pytest.mark.parametrize("grid_fs", [4.0, 6.0, 7.0])
def test_features_do_not_hang_on_the_sample_grid(grid_fs):
    """The curve sampled every 0.5 fs and every 4, 6 or 7 fs (the frame grids of rows at those steps): the first zero
    within 0.01 fs, the first minimum within 0.05 fs and 3e-4 in value of the 0.5-fs reading, where the lowest sample
    of the 6-fs grid is 0.027 above the minimum (90 times the interpolation's error)."""
    fine = acf_summary(_libration_acf(np.arange(0, 500.5, 0.5)), 0.5e-3)  # (times in ps)
    coarse_c = _libration_acf(np.arange(0, 500.5, grid_fs))
    coarse = acf_summary(coarse_c, grid_fs * 1e-3)
    assert abs(coarse.t_zero - fine.t_zero) < 0.01e-3  # ps
    assert abs(coarse.t_min - fine.t_min) < 0.05e-3 and abs(coarse.c_min - fine.c_min) < 3e-4
    grid_min = coarse_c[np.argmin(coarse_c[:20])]
    if grid_fs == 6.0:
        assert grid_min - fine.c_min > 0.02  # what reading the grid gave
    assert 14e-3 < fine.t_zero < 16e-3 and -0.5 < fine.c_min < -0.43
