"""Rigid atom groups in an openmm.System (openmm_symprk.rigid_molecules), run with every splitting."""
import itertools
import warnings

import numpy as np
import openmm as mm
import openmm.unit as unit
import pytest

from openmm_symprk import SymplecticIntegrator, catalogue
from openmm_symprk.physics.momenta import inertia_tensor
from openmm_symprk.physics.rigid_motion import rigid_body_velocities
from openmm_symprk.rigid import groups as rm
from openmm_symprk.rigid.free_body import hydrogen_peroxide, rigid_water
from openmm_symprk.rigid.groups import RigidGroupError, RigidGroupWarning, make_rigid

REFERENCE = mm.Platform.getPlatformByName("Reference")


def methanol(center=(0.0, 0.0, 0.0)):
    """6 atoms, non-planar: C, O, 3 H on C, 1 H on O (roughly tetrahedral)."""
    pos = np.array([[0.0, 0.0, 0.0], [0.143, 0.0, 0.0],
                    [-0.036, 0.103, 0.0], [-0.036, -0.051, 0.089], [-0.036, -0.051, -0.089],
                    [0.175, 0.090, 0.0]])
    return pos + np.asarray(center, float), np.array([12.011, 15.999, 1.008, 1.008, 1.008, 1.008])


def system_of(masses):
    s = mm.System()
    for m in masses:
        s.addParticle(float(m))
    return s


def pair_distances(pos, atoms):
    return np.array([np.linalg.norm(pos[i] - pos[j]) for i, j in itertools.combinations(atoms, 2)])


# -- what gets built ------------------------------------------------------------------------------------
def test_minimal_constraint_sets():
    pos, m = methanol()
    water, mw = rigid_water(center=(1, 0, 0))
    rod = np.array([[0, 1.0, 0], [0.1, 1.0, 0]])
    allpos = np.vstack([pos, water, rod])
    s = system_of(np.concatenate([m, mw, [14.0, 14.0]]))
    groups = make_rigid(s, allpos, [range(6), [6, 7, 8], [9, 10]])
    assert [g.kind for g in groups] == ["framework", "triangle", "rod"]
    assert [g.n_constraints for g in groups] == [3 * 6 - 6, 3, 1]
    assert s.getNumConstraints() == 12 + 3 + 1
    for g in groups:
        for i, j, d in g.constraints:
            assert d == pytest.approx(np.linalg.norm(allpos[i] - allpos[j]), abs=1e-15)
        # masses, centre of mass and inertia are the atoms' own: nothing moved
        assert g.masses_before == g.masses_after
        assert g.inertia_change == 0.0
        np.testing.assert_array_equal(g.com_before, g.com_after)
    assert [s.getParticleMass(i).value_in_unit(unit.dalton) for i in range(11)] == list(np.concatenate([m, mw, [14.0, 14.0]]))


@pytest.mark.parametrize("n", [4, 5, 7, 12])
def test_framework_is_infinitesimally_rigid(n):
    """3N-6 constraints whose Jacobian has rank 3N-6: only the 6 rigid motions are left free."""
    rng = np.random.default_rng(n)
    pos = rng.uniform(-0.2, 0.2, size=(n, 3))
    plan = rm.plan_rigid_group(pos, np.ones(n))
    assert plan.kind == "framework" and len(plan.pairs) == 3 * n - 6
    G = rm._rigidity_matrix(pos, plan.pairs)
    assert np.linalg.matrix_rank(G) == 3 * n - 6
    # the null space is exactly the rigid motions: translations and rotations satisfy G v = 0
    for axis in np.eye(3):
        assert np.abs(G @ np.tile(axis, n)).max() < 1e-14
        assert np.abs(G @ np.cross(axis, pos).ravel()).max() < 1e-14


def test_helper_angle_force_adds_no_energy_or_force():
    pos, m = methanol()
    s = system_of(m)
    nb = mm.CustomExternalForce("0.5*k*(x^2 + y^2 + z^2)")  # something to compare against
    nb.addGlobalParameter("k", 10.0)
    for i in range(6):
        nb.addParticle(i, [])
    s.addForce(nb)
    make_rigid(s, pos, [range(6)])
    names = [s.getForce(i).getName() for i in range(s.getNumForces())]
    assert rm.ANGLE_FORCE_NAME in names
    angle_force = s.getForce(names.index(rm.ANGLE_FORCE_NAME))
    assert angle_force.getNumAngles() > 0
    assert all(angle_force.getAngleParameters(i)[4].value_in_unit(unit.kilojoule_per_mole / unit.radian ** 2) == 0.0
               for i in range(angle_force.getNumAngles()))
    ctx = mm.Context(s, mm.VerletIntegrator(0.001), REFERENCE)
    ctx.setPositions(pos + 0.01)  # off the equilibrium angles too
    e_all = ctx.getState(getEnergy=True).getPotentialEnergy().value_in_unit(unit.kilojoule_per_mole)
    angle_force.setForceGroup(5)
    ctx.reinitialize(preserveState=True)
    e_angles = ctx.getState(getEnergy=True, groups={5}).getPotentialEnergy().value_in_unit(unit.kilojoule_per_mole)
    f_angles = ctx.getState(getForces=True, groups={5}).getForces(asNumpy=True)._value
    assert e_angles == 0.0 and np.abs(f_angles).max() == 0.0
    assert e_all == pytest.approx(0.5 * 10.0 * np.sum((pos + 0.01) ** 2), rel=1e-12)


# -- every catalogue splitting runs rigid molecules through RATTLE -----------------------------------
def _interacting_scene():
    p1, m1 = methanol()
    p2, m2 = hydrogen_peroxide(center=(0.45, 0.05, 0.0))
    p3, m3 = rigid_water(center=(0.1, 0.4, 0.1))
    pos = np.vstack([p1, p2, p3])
    masses = np.concatenate([m1, m2, m3])
    groups = [list(range(6)), list(range(6, 10)), [10, 11, 12]]
    s = system_of(masses)
    nb = mm.NonbondedForce()
    nb.setNonbondedMethod(mm.NonbondedForce.NoCutoff)
    charges = [-0.2, -0.6, 0.1, 0.1, 0.1, 0.5, -0.4, -0.4, 0.4, 0.4, -0.834, 0.417, 0.417]
    for q in charges:
        nb.addParticle(q, 0.25, 0.4)
    for g in groups:
        for i, j in itertools.combinations(g, 2):
            nb.addException(i, j, 0.0, 1.0, 0.0)
    s.addForce(nb)
    make_rigid(s, pos, groups)
    rng = np.random.default_rng(5)
    vel = np.vstack([rigid_body_velocities(pos[g], masses[g], rng.normal(scale=8.0, size=3),
                                              rng.normal(scale=0.4, size=3)) for g in groups])
    return s, pos, vel, masses, groups


SPLITTINGS = [m.name for m in catalogue.splittings()]


@pytest.fixture(scope="module")
def scene():
    return _interacting_scene()


@pytest.mark.parametrize("method", SPLITTINGS)
def test_every_splitting_keeps_groups_rigid_and_conserves_momenta(scene, method):
    s, pos, vel, masses, groups = scene
    integrator = SymplecticIntegrator(0.001, method, system=s)
    integrator.setConstraintTolerance(1e-12)
    assert integrator.program_info.rattle  # RATTLE was compiled
    ctx = mm.Context(s, integrator, REFERENCE)
    ctx.setPositions(pos)
    ctx.setVelocities(vel)

    def state():
        st = ctx.getState(getPositions=True, getVelocities=True, getEnergy=True)
        x = st.getPositions(asNumpy=True)._value
        v = st.getVelocities(asNumpy=True)._value
        e = (st.getPotentialEnergy() + st.getKineticEnergy()).value_in_unit(unit.kilojoule_per_mole)
        return x, v, e, st.getKineticEnergy().value_in_unit(unit.kilojoule_per_mole)

    x0, v0, e0, ke0 = state()
    integrator.step(100)
    x1, v1, e1, _ = state()
    for g in groups:  # every distance in a group, constrained or not: the group is rigid
        np.testing.assert_allclose(pair_distances(x1, g), pair_distances(pos, g), rtol=0, atol=1e-10)
    P0, P1 = (masses[:, None] * v0).sum(0), (masses[:, None] * v1).sum(0)
    L0, L1 = (masses[:, None] * np.cross(x0, v0)).sum(0), (masses[:, None] * np.cross(x1, v1)).sum(0)
    assert np.linalg.norm(P1 - P0) <= 1e-10 * np.linalg.norm(P0)
    assert np.linalg.norm(L1 - L0) <= 1e-10 * np.linalg.norm(L0)
    assert abs(e1 - e0) < 1e-2 * ke0  # a stable, energy-conserving run (exact values depend on the order)


# -- virtual sites for planar and collinear groups ------------------------------------------------------
def ring(n=6, radius=0.14):
    a = np.arange(n) * 2 * np.pi / n
    return np.c_[radius * np.cos(a), radius * np.sin(a), np.zeros(n)]


def test_planar_group_needs_virtual_sites():
    pos = ring()
    s = system_of([12.0] * 6)
    with pytest.raises(RigidGroupError, match="coplanar.*virtual_sites=True"):
        make_rigid(s, pos, [range(6)])
    assert s.getNumConstraints() == 0  # nothing changed on error


@pytest.mark.parametrize("geometry", ["ring", "skewed-ring", "chain"])
def test_virtual_site_groups_keep_mass_and_centre_of_mass(geometry):
    rng = np.random.default_rng(1)
    if geometry == "chain":
        pos = np.c_[np.array([0.0, 0.11, 0.25, 0.36]), np.zeros(4), np.zeros(4)]
        masses = np.array([12.0, 14.0, 16.0, 1.0])
    else:
        pos = ring()
        masses = np.array([12.0, 1.0, 14.0, 1.0, 16.0, 12.0]) if geometry == "skewed-ring" else np.full(6, 12.0)
    R = np.linalg.qr(rng.normal(size=(3, 3)))[0]
    pos = pos @ R.T + 0.3
    s = system_of(masses)
    with pytest.warns(RigidGroupWarning, match="inertia tensor changed"):
        (g,) = make_rigid(s, pos, [range(len(pos))], virtual_sites=True)
    new = np.array([s.getParticleMass(i).value_in_unit(unit.dalton) for i in range(len(pos))])
    assert new.sum() == pytest.approx(masses.sum(), rel=1e-14)
    np.testing.assert_allclose((new[:, None] * pos).sum(0) / new.sum(), (masses[:, None] * pos).sum(0) / masses.sum(),
                               atol=1e-14)
    assert np.all(new >= 0) and np.count_nonzero(new) == (2 if geometry == "chain" else 3)
    assert all(s.isVirtualSite(i) for i in g.virtual_sites) and g.max_site_error < 1e-14
    # the reported inertia change is the real one (the symmetric ring happens to keep it)
    I_new = inertia_tensor(pos[new > 0], new[new > 0], about="com")
    I_old = inertia_tensor(pos, masses, about="com")
    assert g.inertia_change == pytest.approx(np.linalg.norm(I_new - I_old) / np.linalg.norm(I_old), abs=1e-14)
    if geometry == "skewed-ring":
        assert g.inertia_change > 0.01

    # It moves rigidly under RATTLE (no interactions on the sites: see the module notes).
    integrator, ctx = _spinning(s, pos, new, [3.0, -5.0, 7.0], 0.002, "yoshida-4")
    integrator.step(1)  # the first step projects onto the constraints (exact up to adjusted_constraints)
    x1 = ctx.getState(getPositions=True).getPositions(asNumpy=True)._value
    np.testing.assert_allclose(pair_distances(x1, range(len(pos))), pair_distances(pos, range(len(pos))),
                               rtol=0, atol=1e-7 if g.adjusted_constraints else 1e-12)
    integrator.step(200)
    x = ctx.getState(getPositions=True).getPositions(asNumpy=True)._value
    np.testing.assert_allclose(pair_distances(x, range(len(pos))), pair_distances(x1, range(len(pos))), rtol=0, atol=1e-10)


def _spinning(system, pos, masses, angular_velocity, step_ps, method):
    """(integrator, Reference Context) of a rigid group spinning at ``angular_velocity`` and drifting at
    (0.1, 0.2, 0.3) nm/ps, run by ``method`` through RATTLE at a constraint tolerance of 1e-12."""
    integrator = SymplecticIntegrator(step_ps, method, system=system)
    integrator.setConstraintTolerance(1e-12)
    ctx = mm.Context(system, integrator, REFERENCE)
    ctx.setPositions(pos)
    ctx.setVelocities(rigid_body_velocities(pos, masses, angular_velocity, [0.1, 0.2, 0.3]))
    return integrator, ctx


def test_isosceles_triangle_with_unequal_masses_avoids_settle():
    """HOD: OpenMM would hand the triangle to SETTLE, which assumes equal base masses (NaN); make_rigid moves
    one distance by a float32 ulp so that CCMA takes it, and the molecule then runs rigidly."""
    pos, _ = rigid_water()
    masses = np.array([15.999, 1.008, 2.014])
    s = system_of(masses)
    (g,) = make_rigid(s, pos, [[0, 1, 2]])
    assert len(g.adjusted_constraints) == 1
    (i, j, old, new), = g.adjusted_constraints
    assert old == pytest.approx(np.linalg.norm(pos[i] - pos[j]), abs=1e-16)
    assert 0 < abs(new - old) < 1e-7 * old and np.float32(new) != np.float32(old)
    # plain water (equal base masses) keeps its exact distances: SETTLE is right for it
    (w,) = make_rigid(system_of([15.999, 1.008, 1.008]), pos, [[0, 1, 2]])
    assert w.adjusted_constraints == ()
    integrator, ctx = _spinning(s, pos, masses, [3.0, -20.0, 10.0], 0.001, "verlet")
    integrator.step(500)
    x = ctx.getState(getPositions=True).getPositions(asNumpy=True)._value
    np.testing.assert_allclose([np.linalg.norm(x[a] - x[b]) for a, b, _ in g.constraints],
                               [d for _, _, d in g.constraints], rtol=0, atol=1e-12)


# -- errors -------------------------------------------------------------------------------------------------
def _errs(pos, masses, groups, match, **kw):
    s = system_of(masses)
    n_forces = s.getNumForces()
    with pytest.raises(RigidGroupError, match=match):
        make_rigid(s, pos, groups, **kw)
    assert s.getNumConstraints() == 0 and s.getNumForces() == n_forces


def test_error_messages():
    pos, m = methanol()
    _errs(pos, m, [[0]], "at least 2 atoms")
    _errs(pos, m, [[0, 1, 2], [2, 3]], "atom 2 appears also in group")
    _errs(pos, m, [[0, 1, 1]], "twice")
    _errs(pos, m, [[0, 9]], "not a particle index")
    line = np.c_[np.array([0.0, 0.1, 0.2, 0.3, 0.5, 0.7]), np.zeros(6), np.zeros(6)]
    _errs(line, m, [[0, 1, 2]], "collinear")
    same = pos.copy()
    same[1] = same[0]
    _errs(same, m, [[0, 1, 2, 3]], "same position")


def test_massless_virtual_and_constrained_atoms_are_rejected():
    pos, m = methanol()
    s = system_of(np.r_[m[:5], 0.0])
    with pytest.raises(RigidGroupError, match="massless"):
        make_rigid(s, pos, [range(6)])
    s = system_of(m)
    s.setParticleMass(5, 0.0)
    s.setVirtualSite(5, mm.TwoParticleAverageSite(0, 1, 0.5, 0.5))
    with pytest.raises(RigidGroupError, match="virtual site"):
        make_rigid(s, pos, [range(6)])
    s = system_of(m)
    s.addConstraint(0, 1, 0.143)
    with pytest.raises(RigidGroupError, match="replace_constraints=True"):
        make_rigid(s, pos, [range(6)])
    (g,) = make_rigid(s, pos, [range(6)], replace_constraints=True)  # the internal one is replaced
    assert s.getNumConstraints() == g.n_constraints == 12
    s = system_of(m)
    s.addConstraint(0, 5, 0.2)
    with pytest.raises(RigidGroupError, match="outside"):
        make_rigid(s, pos, [range(5)])


def test_bad_arguments():
    pos, m = methanol()
    with pytest.raises(ValueError, match="rows"):
        make_rigid(system_of(m), pos[:4], [range(4)])
    with pytest.raises(TypeError, match="openmm.System"):
        make_rigid(object(), pos, [range(4)])
    with pytest.raises(ValueError, match="no groups"):
        make_rigid(system_of(m), pos, [])
    # positions as a Quantity work too
    (g,) = make_rigid(system_of(m), pos * unit.nanometer, [range(4)])
    assert g.kind == "framework"


def test_warnings_are_not_raised_for_plain_groups():
    pos, m = methanol()
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        make_rigid(system_of(m), pos, [range(6)])
