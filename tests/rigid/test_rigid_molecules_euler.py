"""Cross-validation: a free rigid molecule in OpenMM (RATTLE) against the exact Euler solution.

Reich's section 5 (docs/theory.md, section 3) reduces RATTLE on SO(3) to a Lie-Poisson map of the body angular
momentum.  Here the constrained Cartesian system is run by SymplecticIntegrator on the Reference platform,
the body-frame angular momentum is read from positions and velocities, and compared with
openmm_symprk.rigid.lie_poisson.exact_solution (Jacobi elliptic functions).
"""
import numpy as np
import pytest

from openmm_symprk.rigid import lie_poisson as rb
from openmm_symprk.rigid.free_body import free_rigid_body, hydrogen_peroxide, rigid_water, run_free_rigid_body

T = 0.5  # ps; the body spins at |ω| ~ 16-18 /ps, i.e. 1.3-1.4 turns
STEPS = [100, 200, 400, 800]  # h = 5 .. 0.625 fs


def errors(body, method, record_every=10):
    """Largest |x(t) - x_exact(t)| / |x0| over the run, for each step count; and the largest |ΔL|/|L|."""
    errs, dL = [], 0.0
    for n in STEPS:
        t, x, L = run_free_rigid_body(body, method, T / n, n, record_every=n // 10)
        exact = rb.exact_solution(body.x0, body.moments, t)
        errs.append(np.abs(x - exact).max() / np.linalg.norm(body.x0))
        dL = max(dL, np.abs(L - L[0]).max() / np.linalg.norm(L[0]))
    return np.array(errs), dL


def slope(errs):
    hs = T / np.array(STEPS)
    return np.polyfit(np.log(hs), np.log(errs), 1)[0]


@pytest.mark.parametrize("omega, regime", [([6.0, -14.0, 9.0], "largest"), ([14.0, -6.0, 3.0], "smallest")])
@pytest.mark.parametrize("method, order", [("verlet", 2), ("yoshida-4", 4)])
def test_rigid_water_follows_the_exact_euler_solution(omega, regime, method, order):
    body = free_rigid_body(*rigid_water(center=(0.3, -0.2, 0.1)), omega)
    assert body.group.kind == "triangle"
    M, x0 = body.moments, body.x0
    assert len(set(np.round(M, 12))) == 3  # an asymmetric top
    # the motion circulates about the axis of the largest / smallest moment, as labelled
    assert (x0 @ x0 > 2 * rb.energy(x0, M) * M[1]) == (regime == "largest")
    # the extracted body angular momentum at t = 0 is x0 = M ω
    t, x, _ = run_free_rigid_body(body, method, 0.001, 0)
    np.testing.assert_allclose(x[0], x0, rtol=1e-12)

    errs, dL = errors(body, method)
    assert np.all(np.diff(errs) < 0)
    assert abs(slope(errs) - order) <= 0.3, (errs, slope(errs))
    assert errs[-1] < (1e-3 if order == 2 else 1e-6)
    assert dL <= 1e-10  # space-frame angular momentum: round-off only


def test_cartesian_rattle_reduces_to_the_lie_poisson_rattle():
    """Theorem 5.1 in practice: for 4 non-coplanar atoms the Cartesian space is exactly R³ x GL(3), so
    OpenMM's RATTLE (verlet with constraints, no forces) and the reduced RATTLE of Example 5.3
    (lie_poisson 'rattle-1', with J the body's second moments) are the same map, step by step."""
    body = free_rigid_body(*hydrogen_peroxide(), [6.0, -14.0, 9.0])
    assert body.group.kind == "framework" and body.group.n_constraints == 6
    h, n = 0.004, 150  # a coarse step: both are far from the exact solution, but equal to each other
    t, x, L = run_free_rigid_body(body, "verlet", h, n, record_every=1)
    reduced = rb.integrate(body.x0, body.moments, h, n, "rattle-1")
    exact = rb.exact_solution(body.x0, body.moments, t)
    scale = np.linalg.norm(body.x0)
    assert np.abs(x - exact).max() / scale > 1e-3
    assert np.abs(x - reduced).max() / scale < 1e-9
    assert np.abs(L - L[0]).max() / np.linalg.norm(L[0]) < 1e-10


def test_rigid_peroxide_converges_with_the_composition_order():
    body = free_rigid_body(*hydrogen_peroxide(), [3.0, -6.0, 14.0])
    for method, order in [("verlet", 2), ("yoshida-4", 4)]:
        errs, dL = errors(body, method)
        assert abs(slope(errs) - order) <= 0.3, (method, errs)
        assert dL <= 1e-10
