"""The native SymPRKIntegrator plugin (platforms/, openmm_symprk.native) against the CustomIntegrator path.

Skipped as a whole, with the loader's reason, when the plugin is not built.  Reference is compared bit
for bit (the two backends run the same operations in the same order); OpenCL (PoCL) within its precision.
"""
import copy

import numpy as np
import openmm as mm
import openmm.unit as unit
import pytest

from helpers import (counted, drift_after, evaluations, reference_context, stiff_diatomic, tip4p_cluster,
                     virtual_site_error)
from openmm_symprk import SymplecticIntegrator, catalogue
from openmm_symprk import plugin
from openmm_symprk.integrators import (NativeMethodError, NativeSymplecticIntegrator, NativeUnavailableError,
                                       SimulationBlowUpError, deserialize)
from helpers import COMMON

needs_native = pytest.mark.skipif(not plugin.available(),
                                  reason=f"native plugin unavailable: {plugin.unavailable_reason()}")

SPLITTINGS = [m.name for m in catalogue.splittings()]
N = NativeSymplecticIntegrator


def _state(ctx):
    st = ctx.getState(getPositions=True, getVelocities=True)
    return (st.getPositions(asNumpy=True).value_in_unit(unit.nanometer),
            st.getVelocities(asNumpy=True).value_in_unit(unit.nanometer / unit.picosecond))


def _run(scene, integrator, steps, platform="Reference", properties=None):
    ctx = scene.context(integrator, platform, properties)
    integrator.step(steps)
    out = _state(ctx)
    del ctx
    return out


def _opencl_ok():
    return COMMON in plugin.platforms()


# -- Reference: the same trajectory as the CustomIntegrator, every explicit method, with and without constraints
@needs_native
@pytest.mark.parametrize("name", SPLITTINGS)
@pytest.mark.parametrize("scene_name", ["water8", "morse", "constrained"])
def test_same_trajectory_as_custom_on_reference(name, scene_name, request):
    scene = request.getfixturevalue(scene_name)
    dt = 1 * unit.femtoseconds
    x1, v1 = _run(scene, N(dt, name, system=scene.system), 30)
    x2, v2 = _run(scene, SymplecticIntegrator(dt, name, system=scene.system, backend="custom"), 30)
    # The two backends execute identical floating-point operations on Reference: bitwise equal in practice;
    # the assertion allows round-off in case a compiler orders an operation differently.
    np.testing.assert_allclose(x1, x2, rtol=0, atol=1e-13)
    np.testing.assert_allclose(v1, v2, rtol=0, atol=1e-10)


@needs_native
@pytest.mark.parametrize("name", ["verlet", "yoshida-4", "blanes-moan-srkn6b-4"])
def test_exact_momentum_matches_custom_on_reference(name, water8):
    dt = 2 * unit.femtoseconds
    x1, v1 = _run(water8, N(dt, name, system=water8.system, exact_momentum=True), 50)
    x2, v2 = _run(water8, SymplecticIntegrator(dt, name, system=water8.system, exact_momentum=True, backend="custom"), 50)
    np.testing.assert_allclose(x1, x2, rtol=0, atol=1e-12)
    np.testing.assert_allclose(v1, v2, rtol=0, atol=1e-9)


@needs_native
@pytest.mark.parametrize("name", ["verlet", "omelyan-2", "yoshida-4", "kahan-li-6"])
def test_same_conservation_figures(name, water8):
    figures = []
    for backend in ("native", "custom"):
        ig = SymplecticIntegrator(2 * unit.femtoseconds, name, system=water8.system, backend=backend)
        ctx = water8.context(ig)
        figures.append(drift_after(ctx, ig, water8.masses(), 300))
        del ctx
    (dp1, dl1), (dp2, dl2) = figures
    assert dl1 <= 1e-10 and dp1 <= 1e-10
    assert abs(dl1 - dl2) <= 1e-13 and abs(dp1 - dp2) <= 1e-13


@needs_native
def test_threaded_loops_are_bitwise_identical(water27, monkeypatch):
    """The per-atom loops on the platform's thread pool give the same numbers as the serial loops."""
    out = []
    for threshold in ("1000000", "0"):
        monkeypatch.setenv("SYMPRK_THREAD_MIN_ATOMS", threshold)
        out.append(_run(water27, N(2 * unit.femtoseconds, "yoshida-4", system=water27.system), 20,
                        "Reference"))
    np.testing.assert_array_equal(out[0][0], out[1][0])
    np.testing.assert_array_equal(out[0][1], out[1][1])


# -- cost -----------------------------------------------------------------------------------------------------


@pytest.mark.parametrize("name", ["verlet", "position-verlet", "omelyan-2", "yoshida-4", "mclachlan-atela-4",
                                  "blanes-moan-srkn6b-4", "kahan-li-6", "kahan-li-8"])
@needs_native
@pytest.mark.parametrize("scene_name", ["water8", "morse"])
def test_force_evaluations_per_step(name, scene_name, request):
    scene = request.getfixturevalue(scene_name)
    system, counter = counted(scene)
    ig = N(1 * unit.femtoseconds, name, system=system)
    ctx = reference_context(system, ig, scene)
    ig.step(1)
    assert evaluations(ig, [counter], 40) == (40 * catalogue[name].force_evals,)
    assert ig.force_evals == catalogue[name].force_evals
    # Reference keeps the cached forces through an energy evaluation: one evaluation for the energy, none more.
    counter.n = 0
    ctx.getState(getEnergy=True)
    ig.step(10)
    assert counter.n == 1 + 10 * catalogue[name].force_evals


# -- OpenCL (PoCL in CI) ---------------------------------------------------------------------------------------
@needs_native
@pytest.mark.skipif(not _opencl_ok(), reason=f"no native {COMMON} kernel here ({COMMON} platform or its build missing)")
@pytest.mark.parametrize("precision,tol", [("double", 1e-5), ("mixed", 1e-5), ("single", 1e-4)])
def test_opencl_matches_reference(precision, tol, water8, morse, constrained):
    for scene in (water8, morse, constrained):
        for name in ("verlet", "yoshida-4"):
            ref = _run(scene, N(1 * unit.femtoseconds, name, system=scene.system), 100)
            ocl = _run(scene, N(1 * unit.femtoseconds, name, system=scene.system), 100, COMMON,
                       {"Precision": precision})
            assert np.abs(ocl[0] - ref[0]).max() < tol, (scene.name, name)


@needs_native
@pytest.mark.skipif(not _opencl_ok(), reason=f"no native {COMMON} kernel here ({COMMON} platform or its build missing)")
def test_opencl_same_program_as_custom_in_double(morse, constrained):
    for scene in (morse, constrained):
        native = N(1 * unit.femtoseconds, "yoshida-4", system=scene.system)
        # the plain reading: the fused launches leave out projections CCMA then makes good to its tolerance only
        # (tests/integrators/test_kernel_fusion.py)
        native.setKernelFusion(native.FuseNone)
        a = _run(scene, native, 100, COMMON, {"Precision": "double"})
        b = _run(scene, SymplecticIntegrator(1 * unit.femtoseconds, "yoshida-4", system=scene.system, backend="custom"),
                 100, COMMON, {"Precision": "double"})
        assert np.abs(a[0] - b[0]).max() < 1e-9 and np.abs(a[1] - b[1]).max() < 1e-7


@needs_native
@pytest.mark.skipif(not _opencl_ok(), reason=f"no native {COMMON} kernel here ({COMMON} platform or its build missing)")
@pytest.mark.parametrize("precision,plain,exact", [("double", 1e-10, 1e-11), ("mixed", 1e-4, 1e-11)])
def test_opencl_conservation(precision, plain, exact, water8):
    for em, bound in ((False, plain), (True, exact)):
        ig = N(2 * unit.femtoseconds, "verlet", system=water8.system, exact_momentum=em)
        ctx = water8.context(ig, COMMON, {"Precision": precision})
        dp, dl = drift_after(ctx, ig, water8.masses(), 500)
        assert dp <= bound and dl <= bound, (precision, em, dp, dl)
        del ctx


@needs_native
@pytest.mark.skipif(not _opencl_ok(), reason=f"no native {COMMON} kernel here ({COMMON} platform or its build missing)")
def test_opencl_exact_momentum_with_hbond_shake():
    """Villin in vacuum, HBonds: OpenCL's SHAKE clusters use float inverse masses, so their impulses leave a net
    momentum and torque (~1e-7 relative over 300 steps); exact momentum removes them after every drift and
    after the velocity projection."""
    from openmm_symprk.systems.scenes import protein_vacuum

    scene = protein_vacuum()
    for em, bound in ((False, None), (True, 1e-12)):
        ig = N(2 * unit.femtoseconds, "verlet", system=scene.system, exact_momentum=em)
        ctx = scene.context(ig, COMMON, {"Precision": "mixed"})
        dp, dl = drift_after(ctx, ig, scene.masses(), 300)
        if bound is not None:
            assert dp <= bound and dl <= bound, (dp, dl)
        del ctx


# -- CPU ----------------------------------------------------------------------------------------------------------
@needs_native
def test_cpu_platform_runs_native(water8):
    assert "CPU" in plugin.platforms()
    ref = _run(water8, N(1 * unit.femtoseconds, "yoshida-4", system=water8.system), 50)
    cpu = _run(water8, N(1 * unit.femtoseconds, "yoshida-4", system=water8.system), 50, "CPU")
    assert np.abs(cpu[0] - ref[0]).max() < 1e-5
    # single-precision forces drift the momenta (~1e-6); the exact-momentum projection (in double) does not
    ig = N(2 * unit.femtoseconds, "yoshida-4", system=water8.system, exact_momentum=True)
    ctx = water8.context(ig, "CPU")
    dp, dl = drift_after(ctx, ig, water8.masses(), 500)
    assert dp <= 1e-12 and dl <= 1e-12


# -- XML, checkpoints ---------------------------------------------------------------------------------------------
@needs_native
def test_xml_round_trip(water8):
    ig = N(1.5 * unit.femtoseconds, "kahan-li-6", system=water8.system, exact_momentum=True)
    ig.setConstraintTolerance(1e-7)
    xml = mm.XmlSerializer.serialize(ig)
    assert 'type="SymPRKIntegrator"' in xml and 'method="kahan-li-6"' in xml
    back = deserialize(xml)
    assert back.getStepSize() == ig.getStepSize()
    assert back.getConstraintTolerance() == ig.getConstraintTolerance()
    assert back.getExactMomentum() and back.getMethodName() == "kahan-li-6"
    assert [(back.getSubstepKind(i), back.getSubstepCoefficient(i)) for i in range(back.getNumSubsteps())] == \
        [(ig.getSubstepKind(i), ig.getSubstepCoefficient(i)) for i in range(ig.getNumSubsteps())]
    a = _run(water8, ig, 20)
    b = _run(water8, back, 20)
    np.testing.assert_array_equal(a[0], b[0])
    np.testing.assert_array_equal(a[1], b[1])


@needs_native
@pytest.mark.parametrize("scene_name", ["water8", "morse"])
def test_checkpoint_continues_bitwise_on_reference(scene_name, request):
    scene = request.getfixturevalue(scene_name)
    ig = N(2 * unit.femtoseconds, "yoshida-4", system=scene.system)
    ctx = scene.context(ig)
    ig.step(25)
    chk = ctx.createCheckpoint()
    ig.step(40)
    straight = _state(ctx)
    ctx.loadCheckpoint(chk)
    assert ig.steps_taken == 25
    ig.step(40)
    again = _state(ctx)
    # and in a new Context with a new integrator
    ig2 = N(2 * unit.femtoseconds, "yoshida-4", system=scene.system)
    ctx2 = mm.Context(scene.system, ig2, mm.Platform.getPlatformByName("Reference"))
    ctx2.loadCheckpoint(chk)
    ig2.step(40)
    fresh = _state(ctx2)
    for got in (again, fresh):
        np.testing.assert_array_equal(straight[0], got[0])
        np.testing.assert_array_equal(straight[1], got[1])
    assert ig2.steps_taken == 65
    with pytest.raises(Exception, match="not written by a SymPRKIntegrator"):
        ctx3 = mm.Context(scene.system, mm.VerletIntegrator(0.001), mm.Platform.getPlatformByName("Reference"))
        ctx3.setPositions(scene.positions)
        chk_verlet = ctx3.createCheckpoint()
        ctx2.loadCheckpoint(chk_verlet)


# -- virtual sites, errors ------------------------------------------------------------------------------------------



def _run_tip4p(method, platform, properties, blocks):
    """The TIP4P cluster run natively by ``method`` in ``blocks`` blocks of 40 steps of 1 fs, the virtual sites
    checked after each (placed to 1e-12 nm): (integrator, context, total energy after each block)."""
    system, pos, vel = tip4p_cluster()
    ig = N(1 * unit.femtoseconds, method, system=system)
    ctx = mm.Context(system, ig, mm.Platform.getPlatformByName(platform), properties)
    ctx.setPositions(pos)
    ctx.setVelocities(vel)
    energies = []
    for _ in range(blocks):
        ig.step(40)
        st = ctx.getState(getPositions=True, getEnergy=True)
        assert virtual_site_error(system, st.getPositions(asNumpy=True).value_in_unit(unit.nanometer)) < 1e-12
        energies.append((st.getKineticEnergy() + st.getPotentialEnergy()).value_in_unit(unit.kilojoule_per_mole))
    return ig, ctx, energies


@needs_native
@pytest.mark.skipif(not _opencl_ok(), reason=f"no native {COMMON} kernel here ({COMMON} platform or its build missing)")
def test_opencl_virtual_sites_and_checkpoint():
    ig, ctx, energies = _run_tip4p("yoshida-4", COMMON, {"Precision": "double"}, 3)
    assert max(energies) - min(energies) < 0.05
    chk = ctx.createCheckpoint()
    ig.step(30)
    a = _state(ctx)
    ctx.loadCheckpoint(chk)
    ig.step(30)
    b = _state(ctx)
    np.testing.assert_array_equal(a[0], b[0])
    assert ig.steps_taken == 150


@needs_native
def test_virtual_sites_follow_their_parents():
    """TIP4P-Ew waters: the site is placed after every step (and before each force evaluation inside the
    step: the energy is conserved, unlike the CustomIntegrator path's, which sees sites one drift behind)."""
    _, _, energies = _run_tip4p("verlet", "Reference", {}, 5)
    assert max(energies) - min(energies) < 0.05


@needs_native
def test_blow_up_names_the_first_bad_step():
    system = stiff_diatomic()
    h = 1.7 / np.sqrt(2 * 1.0e5)  # h*omega = 1.7, beyond yoshida-4's stability limit 1.5734

    def run():
        ig = N(h, "yoshida-4", system=system)
        ctx = mm.Context(system, ig, mm.Platform.getPlatformByName("Reference"))
        ctx.setPositions([mm.Vec3(0, 0, 0), mm.Vec3(0.11, 0, 0)])
        return ig, ctx

    ig, ctx = run()
    with pytest.raises(SimulationBlowUpError, match=r"step (\d+) with method 'yoshida-4'.*native backend") as info:
        ig.step(1000)
    import re

    step = int(re.search(r"step (\d+)", str(info.value)).group(1))
    assert 1 < step < 1000 and ig.getBlowUpStep() == 0  # reported, so cleared
    ig2, ctx2 = run()
    ig2.step(step - 1)
    v = ctx2.getState(getVelocities=True).getVelocities(asNumpy=True)._value
    assert np.all(np.isfinite(v))  # the step named is the first non-finite one


@needs_native
def test_errors(water8):
    with pytest.raises(ValueError, match="positive"):
        N(-1 * unit.femtoseconds, "verlet")
    with pytest.raises(TypeError, match="not a time"):
        N(1 * unit.nanometer, "verlet")
    with pytest.raises(Exception, match="Did you mean"):
        N(1 * unit.femtoseconds, "verlett")
    with pytest.raises(NativeMethodError, match="splittings and compositions only"):
        N(1 * unit.femtoseconds, "gauss-2")
    periodic = copy.deepcopy(water8.system)
    periodic.setDefaultPeriodicBoxVectors(mm.Vec3(3, 0, 0), mm.Vec3(0, 3, 0), mm.Vec3(0, 0, 3))
    for f in periodic.getForces():
        if isinstance(f, mm.NonbondedForce):
            f.setNonbondedMethod(mm.NonbondedForce.CutoffPeriodic)
    with pytest.warns(UserWarning, match="periodic"), pytest.raises(ValueError, match="no periodic box"):
        N(1 * unit.femtoseconds, "verlet", system=periodic, exact_momentum=True)
    ig = N(1 * unit.femtoseconds, "verlet")
    assert isinstance(ig, N) and isinstance(ig, mm.Integrator)
    ctx = water8.context(ig)  # noqa: F841
    with pytest.raises(mm.OpenMMException, match="bound to a Context"):
        ig.setSubsteps([0], [1.0], [-1], [0])


@needs_native
def test_unavailable_reason_is_reported(monkeypatch):
    import openmm_symprk.integrators.native_backend as native_module

    monkeypatch.setattr(plugin._State, "swig", None)
    monkeypatch.setattr(plugin._State, "reason", "test: no plugin")
    monkeypatch.setattr(native_module, "_swig", None)
    assert not plugin.available() and plugin.platforms() == []
    with pytest.raises(NativeUnavailableError, match="test: no plugin.*To fix it"):
        N(1 * unit.femtoseconds, "verlet")
