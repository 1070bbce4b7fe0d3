"""Exact-momentum kicks (openmm_symprk.projection): properties with stated bounds.

* a projected kick changes neither P nor L, even for forces with a large net force and torque;
* on Reference the trajectory is the unprojected one to round-off;
* CPU and OpenCL mixed: |dL|/|L| <= 1e-10 over 2,000 steps on the rigid-water cluster and the protein
  in vacuum, against 1e-9..1e-6 without;
* OpenCL single: the float32 state sets a floor far above 1e-10 (measured ~1e-6); the test records
  the figure and the improvement, not the unreachable target;
* failure cases: rk4 (method error, not round-off: projection cannot help), LangevinMiddleIntegrator,
  CMMotionRemover (L about the origin changes, L about the centre of mass does not).
"""
import numpy as np
import openmm as mm
import openmm.app as app
import openmm.unit as unit
import pytest

from conftest import platform_available
from openmm_symprk import SymplecticIntegrator, plugin
from openmm_symprk.conservation import angular_momentum, linear_momentum
from openmm_symprk.integrators.projection import add_projection_variables, emit_projected_acceleration, set_masses
from openmm_symprk.systems.properties import masses
from helpers import COMMON


def exact_integrator(h, method, system):
    """The CustomIntegrator program with projection.py's steps (the native plugin has its own tests)."""
    return SymplecticIntegrator(h, method, system=system, exact_momentum=True, backend="custom")

pytestmark = pytest.mark.filterwarnings("ignore::UserWarning")

OPENCL = platform_available(COMMON)


@pytest.fixture(scope="module")
def protein():
    from openmm_symprk.systems.scenes import protein_vacuum

    return protein_vacuum()


def _drift(ctx, ig, steps, about="com", warmup=1):
    """(|dL|/|L|, |dP|) over ``steps`` steps (after ``warmup`` steps), float64."""
    if warmup:
        ig.step(warmup)
    L0, P0 = angular_momentum(ctx, about=about), linear_momentum(ctx)
    ig.step(steps)
    L1, P1 = angular_momentum(ctx, about=about), linear_momentum(ctx)
    return float(np.linalg.norm(L1 - L0) / np.linalg.norm(L0)), float(np.linalg.norm(P1 - P0))


def _run(scene, platform, props, steps, exact, method="verlet", h=0.002):
    if exact:
        ig = exact_integrator(h, method, scene.system)
    else:
        ig = SymplecticIntegrator(h, method, system=scene.system, backend="custom")
    ctx = scene.context(ig, platform, props)
    out = _drift(ctx, ig, steps)
    del ctx
    return out


def test_projected_kick_has_no_net_force_or_torque(water8):
    """A kick with a strong external field (net force and torque ~1e3): the projected kick changes
    P and L by less than 1e-12 of what the raw kick changes them by."""
    system = mm.XmlSerializer.clone(water8.system)
    field = mm.CustomExternalForce("-(ax*x + ay*y*x + az*z*y)")
    for p in ("ax", "ay", "az"):
        field.addGlobalParameter(p, 300.0)
    for i in range(system.getNumParticles()):
        field.addParticle(i, [])
    system.addForce(field)
    changes = {}
    for projected in (False, True):
        ig = mm.CustomIntegrator(0.002)
        ig.addPerDofVariable("a", 0.0)
        if projected:
            add_projection_variables(ig)
            set_masses(ig, masses(system))
            emit_projected_acceleration(ig, "a")
        else:
            ig.addComputePerDof("a", "f/m")
        ig.addComputePerDof("v", "v + dt*a")
        ctx = mm.Context(system, ig, mm.Platform.getPlatformByName("Reference"))
        ctx.setPositions(water8.positions)
        ctx.setVelocities(water8.velocities)
        P0, L0 = linear_momentum(ctx), angular_momentum(ctx)
        scale = (float(np.sum(water8.masses()[:, None] * np.abs(water8.velocities))), float(np.linalg.norm(L0)))
        ig.step(1)
        changes[projected] = (np.linalg.norm(linear_momentum(ctx) - P0), np.linalg.norm(angular_momentum(ctx) - L0))
    raw, proj = changes[False], changes[True]
    assert raw[0] > 1.0 and raw[1] > 0.01, raw
    # round-off of the quantities themselves (sum m|v|, |L|): ~1e-16..1e-15 relative
    assert proj[0] < 1e-14 * scale[0] and proj[1] < 1e-13 * scale[1], (raw, proj, scale)


def test_reference_trajectory_unchanged(water8):
    """Exact forces have no net force or torque: projection changes the trajectory by round-off only."""
    out = []
    for exact in (False, True):
        ig = exact_integrator(0.002, "yoshida-4", water8.system) if exact else \
            SymplecticIntegrator(0.002, "yoshida-4", system=water8.system, backend="custom")
        ctx = water8.context(ig)
        ig.step(100)
        st = ctx.getState(getPositions=True, getVelocities=True)
        out.append((st.getPositions(asNumpy=True)._value, st.getVelocities(asNumpy=True)._value))
    assert np.max(np.abs(out[0][0] - out[1][0])) < 1e-11
    assert np.max(np.abs(out[0][1] - out[1][1])) < 1e-9


def test_cached_opening_kick_is_reused_and_invalidated(water8):
    """KDK: the opening kick reuses the previous closing kick; setPositions forces a recomputation."""
    ig = exact_integrator(0.002, "verlet", water8.system)
    ctx = water8.context(ig)
    ig.step(1)
    assert ig.getGlobalVariableByName("proj_chg") != 0  # first step: nothing cached
    ig.step(1)
    assert ig.getGlobalVariableByName("proj_chg") == 0  # same positions and forces: reused
    ctx.setPositions(water8.positions)
    ig.step(1)
    assert ig.getGlobalVariableByName("proj_chg") != 0


def test_masses_and_selectors_survive_serialization(water8):
    """The exact masses are stored at the first step (once the Context has the System's particle count) and
    travel with the integrator's XML from then on."""
    ig = exact_integrator(0.002, "verlet", water8.system)
    ctx = water8.context(ig)  # noqa: F841
    ig.step(1)
    clone = mm.XmlSerializer.deserialize(mm.XmlSerializer.serialize(ig))
    masses = [v[0] for v in clone.getPerDofVariableByName("proj_mass")]
    assert masses == pytest.approx(list(water8.masses()), rel=0, abs=0)
    assert list(clone.getPerDofVariableByName("proj_ex")[0]) == [1.0, 0.0, 0.0]


def test_cpu_water_and_protein_exact(water8, protein):
    if not platform_available("CPU"):
        pytest.skip("CPU platform not available")
    for scene in (water8, protein):
        dl, dp = _run(scene, "CPU", {}, 2000, True)
        assert dl <= 1e-10, (scene.name, dl)
        assert dp <= 1e-8, (scene.name, dp)
        dl_off, _ = _run(scene, "CPU", {}, 300, False)
        assert dl_off > 1e-9, (scene.name, dl_off)  # single-precision force sums


@pytest.mark.skipif(not OPENCL, reason=f"{COMMON} platform not available")
@pytest.mark.parametrize("which", ["water", "protein"])
def test_opencl_mixed_exact(which, water8, protein):
    scene = water8 if which == "water" else protein
    props = {"Precision": "mixed"}
    dl, dp = _run(scene, COMMON, props, 2000, True)
    assert dl <= 1e-10, dl
    dl_off, _ = _run(scene, COMMON, props, 300, False)
    assert dl_off > 1e-9, dl_off


@pytest.mark.skipif(not OPENCL, reason=f"{COMMON} platform not available")
def test_opencl_constraint_impulses_restored_after_every_drift(protein):
    """OpenCL's SHAKE for hydrogen clusters uses float inverse masses: its impulses do not cancel
    (~1e-7 over 300 steps even with projected kicks).  Position Verlet ends its step with a drift,
    whose impulses the compiler's drift restoration removes."""
    props = {"Precision": "mixed"}
    dl, _ = _run(protein, COMMON, props, 300, True, method="position-verlet")
    assert dl <= 1e-12, dl
    dl_off, _ = _run(protein, COMMON, props, 300, False, method="position-verlet")
    assert dl_off > 1e-9, dl_off


@pytest.mark.skipif(not OPENCL, reason=f"{COMMON} platform not available")
def test_opencl_single_floor(water8):
    """Single precision stores x and v in float32: each step rounds them at ~6e-8 relative, so 1e-10
    is out of reach (measured ~1e-6 after 2,000 steps); the projection still removes the systematic
    force-sum and SETTLE part (without: ~1e-4)."""
    props = {"Precision": "single"}
    dl, _ = _run(water8, COMMON, props, 2000, True)
    dl_off, _ = _run(water8, COMMON, props, 2000, False)
    assert dl < 2e-5, dl
    assert dl_off > 10 * dl, (dl_off, dl)


@pytest.mark.skipif(not plugin.available(), reason="native plugin unavailable")
def test_massless_virtual_sites_excluded(water8):
    """TIP4P-Ew (massless M sites): finite velocities, P and L conserved.  The native backend's projection (the
    CustomIntegrator backend refuses a System with virtual sites: it would place them one drift behind)."""
    mod = app.Modeller(water8.topology, water8.positions * unit.nanometer)
    ff = app.ForceField("tip4pew.xml")
    mod.addExtraParticles(ff)
    system = ff.createSystem(mod.topology, nonbondedMethod=app.NoCutoff, removeCMMotion=False)
    ig = SymplecticIntegrator(0.001, "verlet", system=system, exact_momentum=True, backend="native")
    ctx = mm.Context(system, ig, mm.Platform.getPlatformByName("Reference"))
    ctx.setPositions(mod.positions)
    ctx.applyConstraints(1e-10)
    ctx.setVelocitiesToTemperature(200, 1)
    dl, dp = _drift(ctx, ig, 300)
    v = ctx.getState(getVelocities=True).getVelocities(asNumpy=True)._value
    assert np.isfinite(v).all()
    assert dl < 1e-11 and dp < 1e-11, (dl, dp)


def test_failure_rk4_method_error_not_round_off(morse):
    """rk4 is not symplectic: L drifts by the method's truncation error, which projection cannot
    remove (P is a linear invariant: conserved by both)."""
    res = {}
    for exact in (False, True):
        ig = SymplecticIntegrator(0.001, "rk4", system=morse.system, allow_nonsymplectic=True, exact_momentum=exact)
        res[exact] = _drift(morse.context(ig), ig, 2000)
    for exact, (dl, dp) in res.items():
        assert dl > 1e-6, (exact, dl)  # measured 3.7e-5
        assert dp < 1e-11
    assert res[True][0] == pytest.approx(res[False][0], rel=1e-6)


def test_failure_langevin(water8):
    ig = mm.LangevinMiddleIntegrator(150 * unit.kelvin, 1 / unit.picosecond, 2 * unit.femtoseconds)
    dl, dp = _drift(water8.context(ig), ig, 300)
    assert dl > 1e-2 and dp > 1.0, (dl, dp)  # a thermostat exchanges momentum with the bath


def test_failure_cmmotionremover_origin(water8):
    """CMMotionRemover zeroes the centre-of-mass velocity: P and L about the origin change, L about
    the centre of mass is kept (to round-off on Reference)."""
    system = mm.XmlSerializer.clone(water8.system)
    system.addForce(mm.CMMotionRemover(1))
    v = water8.velocities + np.array([0.3, -0.2, 0.1])
    results = {}
    for about in ("com", "origin"):
        ig = SymplecticIntegrator(0.002, "verlet", system=system, backend="custom")
        ctx = mm.Context(system, ig, mm.Platform.getPlatformByName("Reference"))
        ctx.setPositions(water8.positions)
        ctx.setVelocities(v)
        results[about] = _drift(ctx, ig, 300, about=about, warmup=0)
    assert results["com"][0] < 1e-11
    assert results["origin"][0] > 1e-2
    assert results["origin"][1] > 1.0
