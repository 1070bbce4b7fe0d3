"""split_forces puts forces into groups whose energies add up to the whole; force_groups lists them;
check_groups refuses a groups= that leaves forces out or names empty groups."""
import numpy as np
import openmm as mm
import pytest

from openmm_symprk.systems.forcegroups import check_groups, force_groups, split_forces


def _nonbonded(built, method=mm.NonbondedForce.PME):
    """``built`` with charges and Lennard-Jones on every particle (a periodic 2 nm box for PME/Ewald), a
    harmonic angle term and a CMMotionRemover (which belongs to no group)."""
    system = built.system
    nb = mm.NonbondedForce()
    nb.setNonbondedMethod(method)
    n = system.getNumParticles()
    for i in range(n):
        nb.addParticle(0.4 * (-1) ** i, 0.3, 0.5)
    for i in range(n - 1):
        nb.addException(i, i + 1, 0.0, 0.3, 0.0)
    if method in (mm.NonbondedForce.PME, mm.NonbondedForce.Ewald):
        nb.setCutoffDistance(0.8)
        system.setDefaultPeriodicBoxVectors(mm.Vec3(2, 0, 0), mm.Vec3(0, 2, 0), mm.Vec3(0, 0, 2))
    system.addForce(nb)
    angles = mm.HarmonicAngleForce()
    angles.addAngle(0, 1, 2, 2.0, 300.0)
    system.addForce(angles)
    system.addForce(mm.CMMotionRemover())
    return built


def _energy(built, groups=-1):
    ctx = built.context()
    return ctx.getState(getEnergy=True, groups=groups).getPotentialEnergy()._value


def test_reciprocal_space_split(build):
    built = _nonbonded(build.chain())
    total = _energy(built)
    groups = split_forces(built.system, slow="reciprocal", substeps=3)
    assert groups == [(1, 1), (0, 3)]
    assert force_groups(built.system) == {
        0: ["HarmonicBondForce #0", "NonbondedForce #1", "HarmonicAngleForce #2"],
        1: ["NonbondedForce #1 (reciprocal space)"]}
    check_groups(built.system, groups)
    fast, slow = _energy(built, {0}), _energy(built, {1})
    assert fast + slow == pytest.approx(total, rel=1e-10)
    assert abs(slow) > 1e-3 * abs(total)  # the reciprocal part is really in the slow group


def test_nonbonded_split_and_other_groups(build):
    built = _nonbonded(build.chain(), method=mm.NonbondedForce.NoCutoff)
    total = _energy(built)
    assert split_forces(built.system, slow="nonbonded", fast_group=4, slow_group=7) == [(7, 1), (4, 2)]
    assert force_groups(built.system) == {4: ["HarmonicBondForce #0", "HarmonicAngleForce #2"],
                                          7: ["NonbondedForce #1"]}
    assert _energy(built, {4}) + _energy(built, {7}) == pytest.approx(total, rel=1e-10)


def test_named_or_indexed_slow_forces(build):
    built = _nonbonded(build.chain(), method=mm.NonbondedForce.NoCutoff)
    split_forces(built.system, slow=["HarmonicAngleForce"])
    assert force_groups(built.system)[1] == ["HarmonicAngleForce #2"]
    split_forces(built.system, slow=[0])
    assert force_groups(built.system) == {0: ["NonbondedForce #1", "HarmonicAngleForce #2"],
                                          1: ["HarmonicBondForce #0"]}


@pytest.mark.parametrize("kwargs, message", [
    (dict(slow="reciprocal"), "needs a NonbondedForce with PME, LJPME or Ewald"),
    (dict(slow=["MorseForce"]), r"slow forces \['MorseForce'\] are not in the System \(it has CMMotionRemover, "
                                r"HarmonicAngleForce, HarmonicBondForce, NonbondedForce; or give indices 0-3\)"),
    (dict(slow=["CMMotionRemover"]), "no force of the System is slow"),
    (dict(slow=[0, 1, 2]), "every force of the System is slow"),
    (dict(slow=3.5), "slow must be 'reciprocal', 'nonbonded' or a list"),
    (dict(substeps=True), "substeps must be a whole number >= 1, got True"),
    (dict(substeps=0), "substeps must be a whole number >= 1, got 0"),
    (dict(slow="nonbonded", fast_group=2, slow_group=2), "two different groups from 0 to 31, got 2 and 2"),
    (dict(slow="nonbonded", slow_group=32), "two different groups from 0 to 31"),
])
def test_bad_splits_are_refused(build, kwargs, message):
    built = _nonbonded(build.chain(), method=mm.NonbondedForce.NoCutoff)
    with pytest.raises(ValueError, match=message):
        split_forces(built.system, **kwargs)


def test_check_groups_refuses_left_out_and_empty_groups(build):
    built = _nonbonded(build.chain())
    split_forces(built.system)
    with pytest.raises(ValueError, match=r"leaves forces out \(group 1: NonbondedForce #1 \(reciprocal space\)\)"):
        check_groups(built.system, [(0, 2)])
    with pytest.raises(ValueError, match=r"force group\(s\) 5 of groups=.* hold no force of the System"):
        check_groups(built.system, [(1, 1), (0, 2), (5, 4)])


def test_the_groups_drive_a_multiple_time_step_integrator(build):
    """The returned groups= is what SymplecticIntegrator takes: a short run conserves energy."""
    import openmm.unit as unit

    from openmm_symprk import SymplecticIntegrator

    built = _nonbonded(build.chain(), method=mm.NonbondedForce.NoCutoff)
    built.system.removeForce(3)  # the CMMotionRemover
    groups = split_forces(built.system, slow="nonbonded", substeps=2)
    integrator = SymplecticIntegrator(0.5 * unit.femtoseconds, "verlet", system=built.system, groups=groups)
    ctx = built.context(integrator)
    ctx.setVelocitiesToTemperature(300.0, 3)

    def energy():
        s = ctx.getState(getEnergy=True)
        return s.getPotentialEnergy()._value + s.getKineticEnergy()._value

    e0 = energy()
    integrator.step(100)
    state = ctx.getState(getPositions=True)
    assert np.abs(state.getPositions(asNumpy=True)._value - built.positions).max() > 1e-3
    assert abs(energy() - e0) < 1e-2 * 15 * 0.5 * 0.0083145 * 300  # small against kT per dof
