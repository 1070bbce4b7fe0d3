"""The rigid-body engine (NO_SQUISH-type Lie-Poisson splitting, forces from OpenMM) on a spinning rigid-water
cluster in vacuum: rigidity exact, momentum and angular momentum to round-off, energy error of order 2, and
the same dynamics as RATTLE (SETTLE) Verlet inside OpenMM to O(h^2)."""
import numpy as np
import openmm.unit as unit
import pytest

from openmm_symprk import SymplecticIntegrator
from openmm_symprk.physics import angular_momentum, linear_momentum
from openmm_symprk.rigid.bodies import RigidBodies, rigid_body_state
from openmm_symprk.systems.scenes import water_cluster


@pytest.fixture(scope="module")
def cluster():
    sc = water_cluster(8, temperature=200.0, angular_velocity=(0.0, 1.0, 3.0), seed=4)
    return sc, [[3 * i, 3 * i + 1, 3 * i + 2] for i in range(8)]


def _engine(sc, mols, h_ps, method="verlet"):
    return RigidBodies(sc.system, sc.positions, sc.velocities, mols, h_ps, method, "Reference")


def test_state_round_trip_is_exact(cluster):
    sc, mols = cluster
    eng = _engine(sc, mols, 0.001)
    assert np.abs(eng.positions() - sc.positions).max() < 1e-14
    assert np.abs(eng.velocities() - sc.velocities).max() < 1e-12


def test_rigidity_and_momenta_conserved_to_round_off(cluster):
    sc, mols = cluster
    eng = _engine(sc, mols, 0.002)
    m = sc.masses()
    p0, l0 = linear_momentum(sc.velocities, m), angular_momentum(sc.positions, sc.velocities, m, about="origin")
    d0 = [np.linalg.norm(sc.positions[a] - sc.positions[b]) for g in mols for a, b in ((g[0], g[1]), (g[0], g[2]), (g[1], g[2]))]
    eng.step(500)
    x, v = eng.positions(), eng.velocities()
    d1 = [np.linalg.norm(x[a] - x[b]) for g in mols for a, b in ((g[0], g[1]), (g[0], g[2]), (g[1], g[2]))]
    assert np.abs(np.subtract(d1, d0)).max() < 1e-13
    scale = np.abs(l0).max()
    assert np.abs(linear_momentum(v, m) - p0).max() < 1e-10
    assert np.abs(angular_momentum(x, v, m, about="origin") - l0).max() < 1e-10 * max(scale, 1.0)
    assert eng.force_evaluations == 501  # first same as last: one evaluation per step


def _energy_error(sc, mols, h_ps, t_ps=0.4, method="verlet"):
    eng = _engine(sc, mols, h_ps, method)
    e0 = eng.kinetic_energy() + eng.potential_energy()
    errs = []
    for _ in range(8):
        eng.step(int(round(t_ps / 8 / h_ps)))
        errs.append(abs(eng.kinetic_energy() + eng.potential_energy() - e0))
    return max(errs)


def test_energy_error_is_second_order(cluster):
    sc, mols = cluster
    e1, e2 = _energy_error(sc, mols, 0.002), _energy_error(sc, mols, 0.001)
    order = np.log2(e1 / e2)
    assert 1.7 < order < 2.3, (e1, e2)


def test_same_dynamics_as_rattle_verlet_to_second_order(cluster):
    """Both are second order and start from one state: their difference after 0.1 ps shrinks 4x per halving."""
    sc, mols = cluster
    diffs = []
    for h in (0.002, 0.001):
        eng = _engine(sc, mols, h)
        n = int(round(0.1 / h))
        eng.step(n)
        integ = SymplecticIntegrator(h * unit.picoseconds, "verlet", system=sc.system)
        ctx = sc.context(integ, "Reference")
        integ.step(n)
        x = ctx.getState(getPositions=True).getPositions(asNumpy=True).value_in_unit(unit.nanometer)
        diffs.append(np.abs(np.asarray(x) - eng.positions()).max())
        del ctx
    assert 3.0 < diffs[0] / diffs[1] < 5.0, diffs


def test_bad_input_is_refused(cluster):
    sc, mols = cluster
    with pytest.raises(ValueError, match="step_ps must be positive"):
        _engine(sc, mols, 0.0)
    with pytest.raises(ValueError, match="in no molecule"):
        RigidBodies(sc.system, sc.positions, sc.velocities, mols[:-1], 0.001, "verlet", "Reference")
    with pytest.raises(ValueError, match="not a kick/drift splitting"):
        _engine(sc, mols, 0.001, method="gauss-2")
    x = np.array([[0.0, 0, 0], [0.1, 0, 0], [0.2, 0, 0]])
    with pytest.raises(ValueError, match="linear"):
        rigid_body_state(x, np.zeros((3, 3)), np.array([16.0, 1.0, 1.0]), [[0, 1, 2]])
