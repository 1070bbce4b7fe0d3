"""Multiple time stepping in OpenMM, both backends: OpenMM's MTSIntegrator reproduced, momentum conserved, orders,
force evaluations per group counted, the force-group helper and its errors."""
import copy
import warnings

import numpy as np
import openmm as mm
import openmm.unit as unit
import pytest
from openmm.mtsintegrator import MTSIntegrator

from helpers import Counter, drift_after, evaluations, measure_order, reference_context
from openmm_symprk import SymplecticIntegrator, plugin
from openmm_symprk.methods.respa import MTSError
from openmm_symprk.systems.forcegroups import check_groups, force_groups, split_forces

BACKENDS = ["custom", pytest.param("native", marks=pytest.mark.skipif(
    not plugin.available(), reason=f"native plugin unavailable: {plugin.unavailable_reason()}"))]


def _split(scene, substeps=2):
    """Non-bonded forces slow for water; for the Morse molecule (bonded only) its angles and 1-4 pair."""
    system = mm.XmlSerializer.clone(scene.system)
    slow = "nonbonded" if scene.name.startswith("water") else ["CustomAngleForce", 2]
    return system, split_forces(system, slow=slow, substeps=substeps)


def _run(system, scene, integrator, steps, tolerance=1e-10):
    integrator.setConstraintTolerance(tolerance)
    ctx = mm.Context(system, integrator, mm.Platform.getPlatformByName("Reference"))
    ctx.setPositions(scene.positions)
    ctx.setVelocities(scene.velocities)
    integrator.step(steps)
    st = ctx.getState(getPositions=True, getVelocities=True)
    return st.getPositions(asNumpy=True)._value, st.getVelocities(asNumpy=True)._value


@pytest.mark.parametrize("backend", BACKENDS)
@pytest.mark.parametrize("scene_name", ["water8", "morse"])
def test_verlet_in_verlet_reproduces_openmms_mtsintegrator(backend, scene_name, request):
    """To round-off, not bit for bit: both compute the same r-RESPA step, but this package merges adjacent kicks
    of one group into one update (v + 0.5*dt*f/m instead of two quarter kicks) and, like RATTLE, projects the
    velocities once per step instead of after every inner drift (a no-op in exact arithmetic)."""
    scene = request.getfixturevalue(scene_name)
    system, groups = _split(scene, substeps=4)
    h = 2 * unit.femtoseconds
    ref = _run(system, scene, MTSIntegrator(h, groups), 200)
    ours = _run(system, scene, SymplecticIntegrator(h, "verlet", system=system, groups=groups, backend=backend), 200)
    assert np.abs(ours[0] - ref[0]).max() < 1e-11 and np.abs(ours[1] - ref[1]).max() < 1e-8


@pytest.mark.skipif(not plugin.available(), reason="native plugin unavailable")
@pytest.mark.parametrize("outer,inner", [("omelyan-2", "verlet"), ("yoshida-4", "pefrl"), ("pefrl", "yoshida-4")])
def test_both_backends_run_the_same_mts_program(outer, inner, water8):
    system, groups = _split(water8, substeps=2)
    runs = [_run(system, water8, SymplecticIntegrator(2 * unit.femtoseconds, outer, system=system, groups=groups,
                                                      inner_method=inner, backend=b), 50)
            for b in ("native", "custom")]
    np.testing.assert_allclose(runs[0][0], runs[1][0], rtol=0, atol=1e-13)
    np.testing.assert_allclose(runs[0][1], runs[1][1], rtol=0, atol=1e-10)


@pytest.mark.parametrize("backend", BACKENDS)
def test_momentum_is_conserved_to_round_off_with_the_group_split(backend, water27):
    """Each force group of an isolated System is translation and rotation invariant: every kick keeps P and L."""
    system, groups = _split(water27, substeps=3)
    ig = SymplecticIntegrator(3 * unit.femtoseconds, "omelyan-2", system=system, groups=groups, inner_method="verlet",
                              backend=backend)
    ctx = mm.Context(system, ig, mm.Platform.getPlatformByName("Reference"))
    ctx.setPositions(water27.positions)
    ctx.setVelocities(water27.velocities)
    dp, dl = drift_after(ctx, ig, water27.masses(), 300)
    assert dp < 1e-10 and dl < 1e-10, (dp, dl)  # the bound of the single-level tests: ~2000 SETTLE solves


@pytest.mark.parametrize("outer,order", [("verlet", 2), ("yoshida-4", 4)])
def test_order_of_an_mts_composition_in_openmm(outer, order, morse):
    """The Morse bonds fast, the angles and the 1-4 pair slow; outer and inner the same method."""
    system = mm.XmlSerializer.clone(morse.system)
    groups = split_forces(system, slow=["CustomAngleForce", 2], substeps=2)
    scene = copy.copy(morse)
    scene.system = system
    orders, _ = measure_order(scene, lambda h: SymplecticIntegrator(h, outer, system=system, groups=groups), 0.02,
                              steps=(8, 16, 32, 64))
    assert abs(orders[-1] - order) < 0.3, orders


def _counted(scene, substeps):
    system, groups = _split(scene, substeps=substeps)
    counters = {}
    for g, _ in groups:
        counters[g] = Counter()
        f = mm.PythonForce(counters[g])
        f.setForceGroup(g)
        system.addForce(f)
    return system, groups, counters


@pytest.mark.parametrize("backend", BACKENDS)
def test_force_evaluations_per_group_are_counted(backend, water8):
    """Native: every group only where a drift came between two of its kicks (per-group force cache): exactly
    the counts of the sequence.  CustomIntegrator: OpenMM keeps one group's forces across steps, so the fast
    group is evaluated once more per step, as in OpenMM's own MTSIntegrator."""
    system, groups, counters = _counted(water8, 4)
    ig = SymplecticIntegrator(2 * unit.femtoseconds, "verlet", system=system, groups=groups, backend=backend)
    assert ig.resolved.evaluations == {(1,): 1, (0,): 4} and ig.program_info.method is ig.resolved
    ref = MTSIntegrator(2 * unit.femtoseconds, groups)
    counts = {}
    for name, integrator in (("ours", ig), ("openmm", ref)):
        ctx = reference_context(system, integrator, water8)  # noqa: F841 (kept alive while stepping)
        integrator.step(2)
        counts[name] = evaluations(integrator, (counters[1], counters[0]), 10)
    assert counts["ours"] == (10, 40 if backend == "native" else 50)  # (slow, fast)
    assert counts["openmm"] == (10, 50)


def test_split_forces_and_group_checks(water8):
    system = mm.XmlSerializer.clone(water8.system)
    with pytest.raises(ValueError, match="no reciprocal space"):
        split_forces(system, slow="reciprocal")
    assert split_forces(system, slow="nonbonded", substeps=3) == [(1, 1), (0, 3)]
    assert set(force_groups(system)) == {0, 1}
    check_groups(system, [(1, 1), (0, 3)])
    with pytest.raises(ValueError, match="leaves forces out.*group 0"):
        check_groups(system, [(1, 1)])
    with pytest.raises(ValueError, match="hold no force"):
        check_groups(system, [(1, 1), (0, 2), (5, 4)])
    with pytest.raises(ValueError, match="not in the System"):
        split_forces(system, slow=["AmoebaVdwForce"])
    with pytest.raises(ValueError, match="substeps"):
        split_forces(system, substeps=0)


def test_split_forces_puts_pme_reciprocal_space_in_the_slow_group():
    from openmm_symprk.systems.scenes import water_box

    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        system, _, _ = water_box("tip3p", box_nm=2.0, cutoff_nm=0.9)
    groups = split_forces(system, slow="reciprocal", substeps=2)
    nb = next(f for f in system.getForces() if isinstance(f, mm.NonbondedForce))
    assert groups == [(1, 1), (0, 2)] and nb.getReciprocalSpaceForceGroup() == 1 and nb.getForceGroup() == 0
    assert any("reciprocal" in n for n in force_groups(system)[1])


@pytest.mark.parametrize("backend", BACKENDS)
def test_mts_errors(backend, water8):
    system, groups = _split(water8)
    with pytest.raises(ValueError, match="leaves forces out"):
        SymplecticIntegrator(0.002, "verlet", system=system, groups=[(1, 1)], backend=backend)
    with pytest.raises(MTSError, match="substeps 0"):
        SymplecticIntegrator(0.002, "verlet", system=system, groups=[(1, 1), (0, 0)], backend=backend)
    with pytest.raises(ValueError, match="needs groups="):
        SymplecticIntegrator(0.002, "verlet", system=system, inner_method="pefrl", backend=backend)
    with pytest.raises(MTSError, match="general.*tableau"):
        SymplecticIntegrator(0.002, "verlet", system=system, groups=groups, inner_method="gauss-2", backend=backend)
