"""Facts of a System against hand counts: degrees of freedom (constraints, virtual sites, massless particles,
CMMotionRemover; also against the temperature OpenMM's StateDataReporter prints), constraint violations,
molecules, signatures."""
import copy
import io

import numpy as np
import openmm as mm
import openmm.app as app
import pytest

from openmm_symprk.systems.properties import (constraint_arrays, constraint_violation, degrees_of_freedom,
                                              force_names, frozen_particles, masses, molecules, signature,
                                              virtual_sites)

R_KJ = 0.00831446261815324  # kJ/mol/K


def _with(built, *, cmm=False, frozen=0):
    """``built`` with a CMMotionRemover and/or ``frozen`` massless particles (not virtual sites) added."""
    system = copy.deepcopy(built.system)
    x = list(built.positions)
    for k in range(frozen):
        system.addParticle(0.0)
        x.append([0.5, 0.5 + 0.3 * k, 0.5])
    if cmm:
        system.addForce(mm.CMMotionRemover())
    built = copy.copy(built)
    built.system, built.positions = system, np.array(x)
    return built


CASES = {  # name -> (how to build it, degrees of freedom counted by hand)
    "5 free particles": (lambda b: b.chain(), 15),
    "2 constraints": (lambda b: b.chain(constraints=[(0, 1), (2, 3)]), 15 - 2),
    "CMMotionRemover": (lambda b: _with(b.chain(constraints=[(0, 1), (2, 3)]), cmm=True), 15 - 2 - 3),
    "3 TIP4P waters": (lambda b: b.tip4p_waters(3), 3 * (9 - 3)),  # the M sites carry no degree of freedom
    "2 frozen atoms": (lambda b: _with(b.chain(), frozen=2), 15),
    "massless in a chain": (lambda b: b.chain(masses=(12.0, 0.0, 12.0, 16.0)), 9),
    "all at once": (lambda b: _with(b.tip4p_waters(2), cmm=True, frozen=1), 2 * 6 - 3),
}


@pytest.mark.parametrize("case", sorted(CASES))
def test_degrees_of_freedom_by_hand(build, case):
    make, expected = CASES[case]
    assert degrees_of_freedom(make(build).system) == expected


@pytest.mark.parametrize("case", sorted(CASES))
def test_degrees_of_freedom_agree_with_openmm_state_data_reporter(build, case):
    """OpenMM prints T = 2 KE / (dof R): the dof it used is 2 KE / (R T)."""
    built = CASES[case][0](build)
    sim = app.Simulation(built.topology, built.system, mm.VerletIntegrator(0.001),
                         mm.Platform.getPlatformByName("Reference"))
    sim.context.setPositions(built.positions)
    sim.context.setVelocitiesToTemperature(300.0, 7)
    out = io.StringIO()
    reporter = app.StateDataReporter(out, 1, kineticEnergy=True, temperature=True)
    reporter.report(sim, sim.context.getState(getEnergy=True))
    ke, temperature = (float(v) for v in out.getvalue().strip().splitlines()[-1].split(","))
    assert 2 * ke / (R_KJ * temperature) == pytest.approx(degrees_of_freedom(built.system), rel=1e-9)


def test_virtual_sites_massless_particles_and_masses(build):
    built = _with(build.tip4p_waters(2), frozen=2)
    assert virtual_sites(built.system) == [3, 7]
    assert frozen_particles(built.system) == [8, 9]  # massless, not virtual sites
    m = masses(built.system)
    assert m.dtype == np.float64 and m.shape == (10,)
    np.testing.assert_array_equal(m[[0, 1, 2, 3]], [15.99943, 1.007947, 1.007947, 0.0])
    assert force_names(_with(built, cmm=True).system) == ["CMMotionRemover"]


def test_constraint_arrays_and_violation(build):
    built = build.tip4p_waters(2)
    i, j, d = constraint_arrays(built.system)
    np.testing.assert_array_equal(i, [0, 0, 1, 4, 4, 5])
    np.testing.assert_array_equal(j, [1, 2, 2, 5, 6, 6])
    assert d[0] == pytest.approx(0.09572)
    x = built.positions.copy()
    assert constraint_violation(x, built.system) < 1e-12
    x[5] = x[4] + 1.01 * (x[5] - x[4])  # the second water's first O-H 1 % too long (and its H-H off too)
    r_hh = np.linalg.norm(x[6] - x[5])
    expected = max(0.01, abs(r_hh - d[5]) / d[5])
    assert constraint_violation(x, built.system) == pytest.approx(expected, rel=1e-9)
    assert constraint_violation(x, (i, j, d)) == constraint_violation(x, built.system)  # arrays or System
    assert constraint_violation(x, build.chain().system) == 0.0  # no constraints


def test_molecules_from_system_topology_and_context_agree(build):
    built = build.tip4p_waters(3)
    expected = [[0, 1, 2, 3], [4, 5, 6, 7], [8, 9, 10, 11]]
    by_system = [g.tolist() for g in molecules(built.system)]  # constraints and virtual-site parents
    assert by_system == expected
    ctx = built.context()
    assert [g.tolist() for g in molecules(ctx)] == expected
    # the Topology has O-H bonds only: the M sites are molecules of their own there
    assert [g.tolist() for g in molecules(built.topology)] == [[0, 1, 2], [3], [4, 5, 6], [7], [8, 9, 10], [11]]
    with pytest.raises(TypeError, match="got str"):
        molecules("water")


def test_molecules_from_angles_alone():
    system = mm.System()
    for _ in range(5):
        system.addParticle(1.0)
    angles = mm.HarmonicAngleForce()
    angles.addAngle(0, 2, 4, 1.9, 100.0)
    system.addForce(angles)
    assert [g.tolist() for g in molecules(system)] == [[0, 2, 4], [1], [3]]


def test_signature_names_what_differs(build):
    built = build.tip4p_waters(2)
    sig = signature(built.system)
    assert sig.mismatch(signature(copy.deepcopy(built.system))) == []
    assert sig.total_mass == pytest.approx(2 * (15.99943 + 2 * 1.007947))
    heavier = copy.deepcopy(built.system)
    heavier.setParticleMass(1, 2.014)
    assert sig.mismatch(signature(heavier)) == ["other masses"]
    bigger = _with(built, frozen=1).system
    assert sig.mismatch(signature(bigger)) == ["9 particles instead of 8"]
    plain = build.chain(masses=(1.0,) * 8).system
    assert sig.mismatch(signature(plain)) == ["no constraints", "no virtual sites", "other masses"]
