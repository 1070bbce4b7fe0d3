"""Float64 diagnostics (openmm_symprk.conservation) against direct numpy formulas and known cases."""
import numpy as np
import openmm as mm
import openmm.unit as unit
import pytest

from openmm_symprk import SymplecticIntegrator
from openmm_symprk.conservation import (angular_momentum, constraint_violation, degrees_of_freedom, diagnostics,
                                        energies, kinetic_energy, linear_momentum, masses_of, molecule_angular_momentum,
                                        molecules)


def _ctx(scene):
    ig = SymplecticIntegrator(0.001, "verlet", system=scene.system)
    return scene.context(ig)


def test_momenta_match_numpy(water8):
    ctx = _ctx(water8)
    m, x, v = water8.masses(), water8.positions, water8.velocities
    P = (m[:, None] * v).sum(0)
    c = (m[:, None] * x).sum(0) / m.sum()
    assert np.allclose(linear_momentum(ctx), P, rtol=0, atol=1e-12)
    assert np.allclose(angular_momentum(ctx), (m[:, None] * np.cross(x - c, v)).sum(0), rtol=1e-13, atol=1e-12)
    assert np.allclose(angular_momentum(ctx, about="origin"), (m[:, None] * np.cross(x, v)).sum(0), rtol=1e-13)
    # L_origin = L_com + M c x V
    V = P / m.sum()
    assert np.allclose(angular_momentum(ctx, about="origin"),
                       angular_momentum(ctx) + m.sum() * np.cross(c, V), rtol=1e-12, atol=1e-12)


def test_state_plus_system_and_arrays(water8):
    ctx = _ctx(water8)
    st = ctx.getState(getPositions=True, getVelocities=True, getEnergy=True)
    with pytest.raises(TypeError, match="system"):
        linear_momentum(st)
    L = angular_momentum(st, system=water8.system)
    assert np.allclose(L, angular_momentum(ctx), rtol=0, atol=0)
    La = angular_momentum((water8.positions, water8.velocities), masses=water8.masses())
    assert np.allclose(L, La, rtol=1e-13)


def test_masses_come_from_the_system(water8):
    """Element masses (topology) differ from force-field masses: the System's are used."""
    m = masses_of(water8.system)
    elem = np.array([a.element.mass.value_in_unit(unit.dalton) for a in water8.topology.atoms()])
    assert np.array_equal(m, water8.masses())
    assert np.max(np.abs(m - elem)) < 0.01


def test_molecules_and_per_molecule_L(water8):
    ctx = _ctx(water8)
    for src in (ctx, water8.system, water8.topology):
        groups = molecules(src)
        assert len(groups) == 8 and all(len(g) == 3 for g in groups)
    Lm = molecule_angular_momentum(ctx)
    assert Lm.shape == (8, 3)
    m, x, v = water8.masses(), water8.positions, water8.velocities
    g = np.arange(3, 6)
    c = (m[g, None] * x[g]).sum(0) / m[g].sum()
    assert np.allclose(Lm[1], (m[g, None] * np.cross(x[g] - c, v[g])).sum(0), rtol=1e-12)


def test_energies_and_constraints(water8):
    ctx = _ctx(water8)
    e = energies(ctx)
    ke = 0.5 * float((water8.masses()[:, None] * water8.velocities ** 2).sum())
    assert e["kinetic"] == pytest.approx(ke, rel=1e-14)
    assert e["total"] == pytest.approx(e["kinetic"] + e["potential"], rel=1e-15)
    assert kinetic_energy(ctx) == pytest.approx(ke, rel=1e-14)
    assert constraint_violation(ctx) < 1e-6  # the scene is constrained to ~3e-8
    x = water8.positions.copy()
    x[1] += [0.001, 0, 0]  # stretch one O-H by ~1%
    ctx.setPositions(x)
    assert constraint_violation(ctx) > 1e-3
    assert degrees_of_freedom(water8.system) == 8 * 6
    s = mm.XmlSerializer.clone(water8.system)
    s.addForce(mm.CMMotionRemover())
    assert degrees_of_freedom(s) == 8 * 6 - 3


def test_diagnostics_single_state(water8):
    ctx = _ctx(water8)
    ctx.getIntegrator().step(5)
    d = diagnostics(ctx)
    assert d.step == 5 and d.time == pytest.approx(0.005)
    assert np.allclose(d.angular_momentum, angular_momentum(ctx), rtol=0, atol=0)
    assert np.allclose(d.angular_momentum_origin, angular_momentum(ctx, about="origin"), rtol=0, atol=0)
    assert d.total == pytest.approx(energies(ctx)["total"], rel=1e-15)
