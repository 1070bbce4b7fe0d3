"""Lie-Poisson integrators for Euler's equations (openmm_symprk.rigid.lie_poisson), pure numpy/scipy."""
import itertools
import math

import numpy as np
import pytest
from scipy.integrate import solve_ivp

from openmm_symprk.rigid import lie_poisson as rb
from openmm_symprk.methods.catalogue import UnknownMethodError
from openmm_symprk.methods.catalogue import methods as catalogue
from openmm_symprk.methods.resolved import resolve
from openmm_symprk.methods.splitting import Splitting, compose

EPS = np.finfo(float).eps
# An asymmetric top with unsorted moments and a generic initial condition.
MOMENTS = np.array([1.8, 0.7, 1.3])  # a physical (non-planar) body: strict triangle inequality
X0 = np.array([0.4, 1.1, -0.8])
LIE_POISSON = [name for name, info in rb.METHODS.items() if info.lie_poisson]
REQUIRED = ["splitting-1", "splitting-2", "splitting-4", "splitting-6", "rattle-1"]


def reference(x0, moments, t_end, t_eval=None):
    """High-accuracy ODE solve of Euler's equations (independent of the module's integrators)."""
    m = np.asarray(moments, float)

    def f(_t, y):
        w = y / m
        return [y[1] * w[2] - y[2] * w[1], y[2] * w[0] - y[0] * w[2], y[0] * w[1] - y[1] * w[0]]

    sol = solve_ivp(f, (0.0, t_end), x0, method="DOP853", rtol=1e-12, atol=1e-14, t_eval=t_eval)
    assert sol.success
    return sol.y.T


def slope(hs, errs):
    return np.polyfit(np.log(hs), np.log(errs), 1)[0]


# -- the method table and the composition code path -----------------------------------------------
def test_method_table_lists_the_required_methods():
    for name in REQUIRED + ["rk4", "kahan-li-8", "yoshida-4", "yoshida-6"]:
        assert name in rb.METHODS
    assert not rb.METHODS["rk4"].lie_poisson
    assert all(rb.METHODS[n].lie_poisson for n in REQUIRED)
    assert [rb.METHODS[n].order for n in ["splitting-1", "splitting-2", "splitting-4", "splitting-6"]] == [
        1, 2, catalogue["yoshida-4"].order, catalogue["yoshida-6"].order]


def test_compositions_go_through_the_catalogue_compose_path():
    base = Splitting([("X1", "1/2"), ("X2", "1/2"), ("X3", 1), ("X2", "1/2"), ("X1", "1/2")])
    assert rb.splitting_of("splitting-2") == base
    for name, comp in [("splitting-4", "yoshida-4"), ("splitting-6", "yoshida-6"), ("kahan-li-8", "kahan-li-8")]:
        s = rb.splitting_of(name)
        assert s == compose(base, catalogue[comp].weights)
        # Consistent (each part sums to one step), symmetric (self-adjoint), and merged: X1 sub-flows of
        # neighbouring base steps were joined, so there are fewer than 5 per weight.
        assert all(abs(float(s.total(lab)) - 1) < 1e-15 for lab in ("X1", "X2", "X3"))
        assert s.is_symmetric()
        assert len(s) == 4 * len(catalogue[comp].weights) + 1
    # catalogue aliases, Method objects and resolved methods give the same composition
    assert rb.splitting_of("yoshida4") == rb.splitting_of("splitting-4")
    assert rb.splitting_of(catalogue["kahan-li-8"]) == rb.splitting_of(resolve("kahan-li-8")) == \
        rb.splitting_of("kahan-li-8")
    with pytest.raises(ValueError, match="unknown rigid-body method 'yoshida-5'.*Did you mean"):
        rb.splitting_of("yoshida-5")
    with pytest.raises(ValueError, match="or a catalogue method, got 42"):
        rb.splitting_of(42)


def test_names_go_through_the_catalogue():
    """Every name but Reich's three integrators of Euler's equations is the catalogue's: aliases work, a misspelt
    name gets the close names of the methods that run on Euler's equations, an MD-only method is refused."""
    assert rb.rigid_body_method("Forest_Ruth").name == "forest-ruth-4-position"
    assert rb.rigid_body_method("SPLITTING_4") == rb.METHODS["splitting-4"]
    assert rb.rigid_body_method(catalogue["rk4"]) == rb.METHODS["rk4"] and not rb.METHODS["rk4"].lie_poisson
    assert set(rb.METHODS) == {"splitting-1", "splitting-2", "splitting-4", "splitting-6", "rattle-1", "rk4",
                               *(m.name for m in catalogue.by_family("composition"))}
    with pytest.raises(UnknownMethodError, match=r"unknown rigid-body method 'splittng-2'\. Did you mean 'splitting-2'"):
        rb.integrate(X0, MOMENTS, 0.1, 1, "splittng-2")
    with pytest.raises(ValueError, match="'pefrl' .splitting. has no rigid-body form"):
        rb.integrate(X0, MOMENTS, 0.1, 1, "pefrl")


# -- the sub-flows: exact, and in the right direction ---------------------------------------------
@pytest.mark.parametrize("axis", [0, 1, 2])
def test_each_subflow_is_the_exact_flow_of_its_hamiltonian(axis):
    """X_i is the flow of H_i = x_i²/(2M_i): x' = x × (x_i/M_i) e_i; compare one long sub-flow with an ODE solve."""
    label = f"X{axis + 1}"
    h = 0.9
    got = rb._run_splitting(X0, 1.0 / MOMENTS, h, 1, Splitting([(label, 1)]))[1]
    e = np.zeros(3)
    e[axis] = 1.0
    sol = solve_ivp(lambda _t, y: np.cross(y, y[axis] / MOMENTS[axis] * e), (0, h), X0,
                    rtol=1e-12, atol=1e-14, method="DOP853")
    np.testing.assert_allclose(got, sol.y[:, -1], rtol=0, atol=1e-11)
    assert got[axis] == X0[axis]  # the rotation axis component is untouched


@pytest.mark.parametrize("method", REQUIRED + ["rk4"])
def test_methods_integrate_forwards_in_time(method):
    # One small step follows the vector field, not its negative ...
    h = 1e-4
    x1 = rb.step(X0, MOMENTS, h, method)
    rhs = rb.euler_rhs(X0, MOMENTS)
    assert np.linalg.norm((x1 - X0) / h - rhs) < 1e-2 * np.linalg.norm(rhs)
    # ... and a run to T lands on x(T), far from x(-T).
    T, n = 3.0, 300
    end = rb.integrate(X0, MOMENTS, T / n, n, method)[-1]
    fwd, back = rb.exact_solution(X0, MOMENTS, [T, -T])
    assert np.linalg.norm(end - fwd) < 0.05 * np.linalg.norm(X0)
    assert np.linalg.norm(end - back) > 0.3 * np.linalg.norm(X0)


def test_a_wrong_rotation_sign_would_be_caught():
    """Flipping the sub-flow angles (negated M⁻¹) integrates backwards: the check above sees it."""
    T, n = 3.0, 300
    wrong = rb._run_splitting(X0, -1.0 / MOMENTS, T / n, n, rb.splitting_of("splitting-2"))[-1]
    fwd, back = rb.exact_solution(X0, MOMENTS, [T, -T])
    assert np.linalg.norm(wrong - back) < 1e-3
    assert np.linalg.norm(wrong - fwd) > 0.3 * np.linalg.norm(X0)


# -- Casimir and energy -----------------------------------------------------------------------------
def _casimir_bound(method, n_steps):
    """Round-off bound: a random walk of a few ulps per exact rotation (1e-13 floor)."""
    if method == "rattle-1":
        return 1e-13
    n_rot = len(rb.splitting_of(method)) * n_steps
    return max(1e-13, 4 * EPS * math.sqrt(n_rot))


@pytest.mark.parametrize("method", LIE_POISSON)
def test_casimir_is_conserved_to_round_off(method):
    n = 10_000 if method in REQUIRED else 2_000
    path = rb.integrate(X0, MOMENTS, 0.05, n, method)
    c = rb.casimir(path)
    drift = np.abs(c / c[0] - 1).max()
    assert drift <= _casimir_bound(method, n), drift


def test_rk4_does_not_conserve_the_casimir():
    n = 10_000
    c = rb.casimir(rb.integrate(X0, MOMENTS, 0.05, n, "rk4"))
    drift = np.abs(c / c[0] - 1).max()
    # Far above what every Lie-Poisson method reaches in the same run (<= 1e-13, above).
    assert drift > 1e4 * 1e-13, drift
    # and it is a drift: monotone growth, the end is the worst point
    assert abs(c[-1] / c[0] - 1) > 0.9 * drift


def _tenths(method, h=0.05, n=10_000):
    e = rb.energy(rb.integrate(X0, MOMENTS, h, n, method), MOMENTS)
    err = np.abs(e / e[0] - 1)
    k = n // 10
    return err[1:k + 1].max(), err[-k:].max()


@pytest.mark.parametrize("method", ["splitting-1", "splitting-2", "splitting-4", "splitting-6"])
def test_energy_error_is_bounded_without_drift(method):
    first, last = _tenths(method)
    assert first > 0
    assert last <= 1.5 * first + 1e-13, (first, last)


def test_rattle_conserves_energy_to_round_off():
    # The potential-free reduced RATTLE is the discrete Moser-Veselov rigid body: it keeps H exactly.
    first, last = _tenths("rattle-1")
    assert max(first, last) < 1e-13


def test_rk4_energy_drifts():
    first, last = _tenths("rk4")
    assert last > 5 * first, (first, last)


# -- orders -----------------------------------------------------------------------------------------
ORDER_LADDERS = {
    "splitting-1": [32, 64, 128, 256],
    "splitting-2": [16, 32, 64, 128],
    "splitting-4": [8, 16, 32, 64],
    "splitting-6": [8, 12, 16, 24],
    "rattle-1": [32, 64, 128, 256],
    "rk4": [16, 32, 64, 128],
    "kahan-li-8": [2, 3, 4, 6],
}


@pytest.mark.parametrize("method", list(ORDER_LADDERS))
def test_measured_order_against_the_exact_solution(method):
    T = 2.0
    exact = rb.exact_solution(X0, MOMENTS, [T])[0]
    ns = np.array(ORDER_LADDERS[method])
    errs = [np.linalg.norm(rb.integrate(X0, MOMENTS, T / n, n, method)[-1] - exact) for n in ns]
    assert min(errs) > 1e3 * EPS  # the ladder stays above round-off
    p = slope(T / ns, errs)
    assert abs(p - rb.METHODS[method].order) <= 0.3, p


def test_rattle_is_second_order_also_for_a_planar_body():
    """Moments on the triangle inequality's edge (planar body, J3 = 0) use the shifted J."""
    M = np.array([1.0, 2.0, 3.0])
    J = rb.second_moments(M)
    assert np.all(J > 0)
    T = 2.0
    exact = rb.exact_solution(X0, M, [T])[0]
    ns = np.array([32, 64, 128])
    errs = [np.linalg.norm(rb.integrate(X0, M, T / n, n, "rattle-1")[-1] - exact) for n in ns]
    assert abs(slope(T / ns, errs) - 2) <= 0.3


def test_second_moments_of_a_physical_body():
    J = rb.second_moments(MOMENTS)
    np.testing.assert_allclose([J[1] + J[2], J[0] + J[2], J[0] + J[1]], MOMENTS, rtol=1e-15)


def test_rattle_step_satisfies_its_defining_equations():
    J = rb.second_moments(MOMENTS)
    h = 0.1
    x1, d = rb.rattle_step(X0, J, h)
    Q, P, lam, mu, pi1 = d["Q"], d["P"], d["lambda"], d["mu"], d["Pi_next"]
    np.testing.assert_allclose(Q.T @ Q, np.eye(3), atol=1e-15)
    assert np.linalg.det(Q) > 0
    np.testing.assert_allclose(lam, lam.T, atol=1e-12)
    np.testing.assert_allclose(mu, mu.T, atol=1e-12)
    np.testing.assert_allclose(P, 0.5 * rb._hat(X0) - 2 * h * lam, atol=1e-15)
    np.testing.assert_allclose(Q, np.eye(3) + h * P / J, atol=1e-15)
    np.testing.assert_allclose(pi1, -pi1.T, atol=1e-14)  # skew
    np.testing.assert_allclose(pi1, 0.5 * rb._hat(x1), atol=1e-14)  # Π_{n+1} ↔ x_{n+1}/2


# -- the exact solution -----------------------------------------------------------------------------
def _regime(x0, moments):
    """'largest' if the motion circulates about the largest-moment axis, else 'smallest'."""
    mid = np.sort(moments)[1]
    return "largest" if x0 @ x0 > 2 * rb.energy(x0, moments) * mid else "smallest"


@pytest.mark.parametrize("perm", list(itertools.permutations(range(3))))
@pytest.mark.parametrize("x_sorted", [[0.3, 0.5, 1.2], [1.2, -0.5, 0.3]])
def test_exact_solution_matches_an_ode_solve(perm, x_sorted):
    """Both regimes (near the largest / smallest axis) for every ordering of the moments."""
    m_sorted = np.array([0.8, 1.5, 2.6])
    perm = list(perm)
    M = m_sorted[perm]
    x0 = np.array(x_sorted)[perm]
    expected = "largest" if x_sorted[2] == 1.2 else "smallest"
    assert _regime(x0, M) == expected
    t = np.linspace(0, 30, 301)
    np.testing.assert_allclose(rb.exact_solution(x0, M, t), reference(x0, M, 30, t), rtol=0, atol=1e-9)


def test_exact_solution_random_cases_and_negative_times():
    rng = np.random.default_rng(7)
    regimes = set()
    for _ in range(20):
        M = rng.uniform(0.3, 3.0, 3)
        x0 = rng.normal(size=3)
        regimes.add(_regime(x0, M))
        t = np.linspace(0, 20, 101)
        np.testing.assert_allclose(rb.exact_solution(x0, M, t), reference(x0, M, 20, t), atol=1e-9 * np.abs(x0).max())
        # backwards in time: x(-t) from x0 solves the reversed equation, i.e. x(t) from x(-T) returns x0
        back = rb.exact_solution(x0, M, [-5.0])[0]
        np.testing.assert_allclose(rb.exact_solution(back, M, [5.0])[0], x0, atol=1e-10)
    assert regimes == {"largest", "smallest"}


@pytest.mark.parametrize("M", [[1.0, 1.0, 2.0], [2.0, 1.0, 2.0], [1.5, 0.5, 0.5]])
def test_exact_solution_symmetric_tops(M):
    M = np.array(M)
    t = np.linspace(0, 20, 101)
    np.testing.assert_allclose(rb.exact_solution(X0, M, t), reference(X0, M, 20, t), atol=1e-9)


def test_exact_solution_degenerate_cases():
    t = np.linspace(0, 10, 11)
    # spherical top and the zero vector: at rest
    np.testing.assert_array_equal(rb.exact_solution(X0, [1.0, 1.0, 1.0], t), np.tile(X0, (11, 1)))
    np.testing.assert_array_equal(rb.exact_solution([0, 0, 0], MOMENTS, t), np.zeros((11, 3)))
    # steady rotations about each principal axis (the middle one is unstable but still steady)
    for axis in range(3):
        x0 = np.zeros(3)
        x0[axis] = 1.3
        np.testing.assert_allclose(rb.exact_solution(x0, MOMENTS, t), np.tile(x0, (11, 1)), atol=1e-15)
    # the separatrix |x|² = 2E M_mid: sorted moments (1, 2, 3) and x1² = x3²/3
    M = np.array([1.0, 2.0, 3.0])
    x0 = np.array([1 / math.sqrt(3), 0.3, 1.0])
    tt = np.linspace(0, 5, 51)
    np.testing.assert_allclose(rb.exact_solution(x0, M, tt), reference(x0, M, 5, tt), atol=1e-9)


def test_exact_solution_conserves_both_invariants():
    t = np.linspace(0, 100, 1001)
    path = rb.exact_solution(X0, MOMENTS, t)
    np.testing.assert_allclose(rb.casimir(path), rb.casimir(X0), rtol=1e-13)
    np.testing.assert_allclose(rb.energy(path, MOMENTS), rb.energy(X0, MOMENTS), rtol=1e-13)


# -- errors -----------------------------------------------------------------------------------------
@pytest.mark.parametrize("moments", [[1.0, 0.0, 2.0], [1.0, -1.0, 2.0], [1.0, 2.0], [1.0, np.nan, 2.0]])
def test_bad_moments_are_rejected(moments):
    with pytest.raises(ValueError, match="moments"):
        rb.integrate(X0, moments, 0.1, 3, "splitting-2")
    with pytest.raises(ValueError, match="moments"):
        rb.exact_solution(X0, moments, [0.0, 1.0])


@pytest.mark.parametrize("h", [0.0, -0.1, np.inf])
def test_bad_step_size_is_rejected(h):
    with pytest.raises(ValueError, match="step size"):
        rb.integrate(X0, MOMENTS, h, 3, "splitting-2")


def test_unknown_method_suggests_close_names():
    with pytest.raises(ValueError, match="Did you mean 'splitting-4'"):
        rb.integrate(X0, MOMENTS, 0.1, 3, "spliting-4")
    with pytest.raises(ValueError, match="Known methods"):
        rb.integrate(X0, MOMENTS, 0.1, 3, "no-such-thing")


def test_other_bad_inputs():
    with pytest.raises(ValueError, match="x0"):
        rb.integrate([1.0, 2.0], MOMENTS, 0.1, 3)
    with pytest.raises(ValueError, match="n_steps"):
        rb.integrate(X0, MOMENTS, 0.1, -1)
    with pytest.raises(ValueError, match="n_steps"):
        rb.integrate(X0, MOMENTS, 0.1, 2.5)
    with pytest.raises(RuntimeError, match="Newton"):
        rb.integrate(10 * X0, MOMENTS, 5.0, 3, "rattle-1")  # far too large a step
