"""Reliability of both backends: what an integrator was compiled for, checkpoints across variants, recovery
after a blow-up, copies, time after setStepSize, virtual sites (a TIP4P-Ew box), and the blow-up threshold.

Each test fails on the behaviour reported before these checks existed (wrong results without a word, or a
false alarm)."""
import copy
import pickle
import warnings

import numpy as np
import openmm as mm
import openmm.unit as unit
import pytest

from conftest import platform_available
from helpers import COMMON, stiff_diatomic
from openmm_symprk import (CheckpointMismatchError, SimulationBlowUpError, SymplecticIntegrator, SystemMismatchError,
                           deserialize, plugin, restore)
from openmm_symprk.integrators import CustomSymplecticIntegrator, NativeSymplecticIntegrator

BACKENDS = ["custom", pytest.param("native", marks=pytest.mark.skipif(
    not plugin.available(), reason=f"native plugin unavailable: {plugin.unavailable_reason()}"))]
needs_opencl = pytest.mark.skipif(not platform_available(COMMON), reason=f"{COMMON} platform not available")


def _positions(ctx):
    return ctx.getState(getPositions=True).getPositions(asNumpy=True).value_in_unit(unit.nanometer)


def _velocities(ctx):
    return ctx.getState(getVelocities=True).getVelocities(asNumpy=True).value_in_unit(unit.nanometer / unit.picosecond)


# -- 1. exact momentum only where it is right ------------------------------------------------------------------------
@pytest.mark.parametrize("backend", BACKENDS)
def test_exact_momentum_needs_system_and_refuses_frozen_atoms(backend, water8):
    with pytest.raises(ValueError, match="needs system="):
        SymplecticIntegrator(0.002, "verlet", backend=backend, exact_momentum=True)
    frozen = copy.deepcopy(water8.system)
    frozen.setParticleMass(0, 0.0)  # a frozen oxygen: a real force on the others, never moved
    with pytest.warns(UserWarning, match="frozen"), pytest.raises(ValueError, match="frozen particles"):
        SymplecticIntegrator(0.002, "verlet", system=frozen, backend=backend, exact_momentum=True)
    field = copy.deepcopy(water8.system)
    pull = mm.CustomExternalForce("0.1*x")
    pull.addParticle(0, [])
    field.addForce(pull)
    with pytest.warns(UserWarning, match="external field"), pytest.raises(ValueError, match="external field"):
        SymplecticIntegrator(0.002, "verlet", system=field, backend=backend, exact_momentum=True)


# -- 2. a Context of another System is refused ----------------------------------------------------------------------
def test_custom_refuses_another_particle_count_before_stepping(morse, water8):
    ig = SymplecticIntegrator(0.001, "verlet", system=morse.system, backend="custom")
    ctx = water8.context(ig)
    with pytest.raises(SystemMismatchError, match="4 particles.*has 24"):
        ig.step(5)
    np.testing.assert_array_equal(_positions(ctx), water8.positions)  # nothing moved


def test_custom_refuses_constraints_it_was_not_compiled_for(morse, constrained):
    ig = SymplecticIntegrator(0.001, "yoshida-4", system=morse.system, backend="custom")  # no constraints
    ctx = constrained.context(ig)  # noqa: F841 (the Context must outlive the steps)
    with pytest.raises(SystemMismatchError, match="without constraints.*has constraints"):
        ig.step(3)


@pytest.mark.skipif(not plugin.available(), reason="native plugin unavailable")
def test_native_refuses_another_system_at_context_creation(morse, water8, constrained):
    ig = SymplecticIntegrator(0.001, "verlet", system=morse.system, backend="native")
    with pytest.raises(mm.OpenMMException, match="set up for a System of 4 particles without constraints.*24 particles"):
        water8.context(ig)
    ig = SymplecticIntegrator(0.001, "verlet", system=morse.system, backend="native")
    with pytest.raises(mm.OpenMMException, match="without constraints, but.*with constraints"):
        constrained.context(ig)


# -- 3. checkpoints across variants -----------------------------------------------------------------------------------
def _checkpoint(scene, **options):
    ig = SymplecticIntegrator(0.002, "verlet", system=scene.system, **options)
    ctx = scene.context(ig)
    ig.step(10)
    return ctx.createCheckpoint()


def test_checkpoint_of_another_program_is_refused_by_the_custom_backend(water8):
    chk = _checkpoint(water8, backend="custom", exact_momentum=True)
    ig = SymplecticIntegrator(0.002, "verlet", system=water8.system, backend="custom")
    ctx = water8.context(ig)
    ctx.loadCheckpoint(chk)
    with pytest.raises(CheckpointMismatchError, match="another integrator program"):
        ig.step(1)
    # the same variant continues
    ig2 = SymplecticIntegrator(0.002, "verlet", system=water8.system, backend="custom", exact_momentum=True)
    ctx2 = water8.context(ig2)
    ctx2.loadCheckpoint(chk)
    ig2.step(5)
    assert ig2.steps_taken == 15


@pytest.mark.skipif(not plugin.available(), reason="native plugin unavailable")
def test_checkpoints_across_backends_and_methods_are_refused(water8):
    native = _checkpoint(water8, backend="native")
    ig = SymplecticIntegrator(0.002, "verlet", system=water8.system, backend="custom")
    ctx = water8.context(ig)
    try:
        ctx.loadCheckpoint(native)
    except mm.OpenMMException:
        pass  # OpenMM may already refuse the stream
    else:
        with pytest.raises(CheckpointMismatchError, match="native backend"):
            ig.step(1)
    custom = _checkpoint(water8, backend="custom")
    ig = SymplecticIntegrator(0.002, "verlet", system=water8.system, backend="native")
    ctx = water8.context(ig)
    with pytest.raises(mm.OpenMMException, match="not written by a SymPRKIntegrator.*backend='custom'"):
        ctx.loadCheckpoint(custom)
    other = SymplecticIntegrator(0.002, "yoshida-4", system=water8.system, backend="native")
    ctx = water8.context(other)
    with pytest.raises(mm.OpenMMException, match="another program.*'verlet'.*'yoshida-4'"):
        ctx.loadCheckpoint(native)


# -- 4. virtual sites: conserved where they run, refused where they would heat --------------------------------------------
def _tip4pew_box():
    """215 rigid TIP4P-Ew waters with PME (1.9 nm box, 0.8 nm cutoff, no CMMotionRemover), minimised on CPU, with
    Maxwell-Boltzmann velocities at 300 K."""
    import openmm.app as app

    from openmm_symprk.systems.prepare import maxwell_boltzmann, minimise

    ff = app.ForceField("tip4pew.xml")
    mod = app.Modeller(app.Topology(), [])
    mod.addSolvent(ff, model="tip4pew", boxSize=mm.Vec3(1.9, 1.9, 1.9) * unit.nanometer)
    system = ff.createSystem(mod.topology, nonbondedMethod=app.PME, nonbondedCutoff=0.8 * unit.nanometer,
                             constraints=app.HBonds, rigidWater=True, removeCMMotion=False)
    pos = minimise(system, mod.positions, platform="CPU", tolerance=10.0)
    return system, pos, maxwell_boltzmann(system, pos, 300.0, 1)


def _energy_excursion(system, pos, vel, ig, steps=400, every=40) -> float:
    """Largest |E(t) - E(0)| (kJ/mol) over ``steps`` NVE steps on CPU."""
    ctx = mm.Context(system, ig, mm.Platform.getPlatformByName("CPU"))
    ctx.setPositions(pos)
    ctx.setVelocities(vel)
    energies = []
    for _ in range(steps // every + 1):
        st = ctx.getState(getEnergy=True)
        energies.append((st.getPotentialEnergy() + st.getKineticEnergy()).value_in_unit(unit.kilojoule_per_mole))
        ig.step(every)
    return float(np.max(np.abs(np.array(energies) - energies[0])))


@pytest.mark.filterwarnings("ignore::openmm_symprk.systems.checks.ConservationWarning")
def test_tip4pew_box_conserves_energy_or_is_refused():
    """A TIP4P-Ew box in NVE at 2 fs (0.8 ps): every backend that accepts it conserves the energy as OpenMM's
    VerletIntegrator does.  The CustomIntegrator backend used to run it with a warning and heated: +238 kJ/mol in
    1 ps (T 300 -> 322 K) where Verlet and the native backend stay within 8, because OpenMM's CustomIntegrator places
    the M sites only at the end of a step on CPU; it now refuses the System by name."""
    system, pos, vel = _tip4pew_box()
    verlet = _energy_excursion(system, pos, vel, mm.VerletIntegrator(0.002))
    refused = []
    for backend in ("custom", "native"):
        if backend == "native" and not plugin.available():
            continue
        try:
            ig = SymplecticIntegrator(0.002, "verlet", system=system, backend=backend)
        except ValueError as exc:  # VirtualSitesError
            assert "virtual site" in str(exc)
            refused.append(backend)
            continue
        excursion = _energy_excursion(system, pos, vel, ig)
        assert excursion < 2 * verlet + 5.0, (backend, excursion, verlet)
    assert refused == ["custom"]


# -- 5. time after setStepSize --------------------------------------------------------------------------------------------
@pytest.mark.parametrize("platform", ["Reference", "CPU", COMMON])
@pytest.mark.parametrize("backend", BACKENDS)
def test_time_follows_setstepsize_mid_run(backend, platform, water8):
    """The native backend reports the time the steps took, on every platform, without a word.  OpenMM's
    CustomIntegrator on Reference/CPU advances the Context's time by the step size the Context was created with, and
    the CustomIntegrator backend cannot reach its Context to set it (it used to find it by scanning the Python heap):
    setStepSize on a bound one warns once (TimeWarning), naming context.reinitialize(preserveState=True), after which
    the time follows the step size on every platform."""
    from openmm_symprk.integrators import TimeWarning

    if not platform_available(platform) or (backend == "native" and platform not in plugin.platforms()):
        pytest.skip(f"no {platform} platform (or no native kernel for it)")
    ig = SymplecticIntegrator(0.002, "verlet", system=water8.system, backend=backend)
    ctx = water8.context(ig, platform, {"Precision": "double"} if platform == COMMON else None)
    ig.step(1)
    if backend == "custom":
        with pytest.warns(TimeWarning, match=r"from 0.002 to 0.001 ps.*reinitialize\(preserveState=True\)"):
            ig.setStepSize(0.001)
        ctx.reinitialize(preserveState=True)

    def change(step):
        ig.setStepSize(step)
        if backend == "custom":
            ctx.reinitialize(preserveState=True)

    with warnings.catch_warnings():
        warnings.simplefilter("error")  # once: no more warnings
        if backend == "native":
            change(0.001)
        ig.step(10)
        assert ctx.getState().getTime().value_in_unit(unit.picosecond) == pytest.approx(0.012, rel=1e-12)
        change(0.0005 * unit.picoseconds)
        ig.step(4)
        assert ctx.getState().getTime().value_in_unit(unit.picosecond) == pytest.approx(0.014, rel=1e-12)
        ctx.setTime(1.0)  # the user's own time is kept too
        ig.step(2)
        assert ctx.getState().getTime().value_in_unit(unit.picosecond) == pytest.approx(1.001, rel=1e-12)
        change(0.002)  # back to the step the Context was created with
        ig.step(3)
        assert ctx.getState().getTime().value_in_unit(unit.picosecond) == pytest.approx(1.007, rel=1e-12)


# -- 6. recovery after a blow-up -------------------------------------------------------------------------------------------
@pytest.mark.parametrize("backend", BACKENDS)
def test_reloading_a_good_state_after_a_blow_up_goes_on(backend):
    system = stiff_diatomic()
    ig = SymplecticIntegrator(2.2 / np.sqrt(2e5), "verlet", system=system, backend=backend)  # h*w = 2.2 > 2
    ctx = mm.Context(system, ig, mm.Platform.getPlatformByName("Reference"))
    ctx.setPositions([mm.Vec3(0, 0, 0), mm.Vec3(0.11, 0, 0)])
    saved = ctx.getState(getPositions=True, getVelocities=True)
    with pytest.raises(SimulationBlowUpError, match="blow-up record is cleared"):
        ig.step(2000)
    ctx.setState(saved)
    ig.setStepSize(1.0 / np.sqrt(2e5))
    ig.step(500)  # no stale alarm
    assert np.all(np.isfinite(_positions(ctx)))


# -- 8. copies ----------------------------------------------------------------------------------------------------------------
@pytest.mark.parametrize("backend", BACKENDS)
@pytest.mark.parametrize("how", ["pickle", "copy", "deepcopy", "xml"])
def test_copies_keep_their_class_and_run_the_same(backend, how, water8):
    ig = SymplecticIntegrator(0.002, "yoshida-4", system=water8.system, backend=backend, exact_momentum=True)
    clone = {"pickle": lambda: pickle.loads(pickle.dumps(ig)), "copy": lambda: copy.copy(ig),
             "deepcopy": lambda: copy.deepcopy(ig),
             "xml": lambda: restore(mm.XmlSerializer.deserialize(mm.XmlSerializer.serialize(ig)))}[how]()
    assert type(clone) is type(ig) and isinstance(clone, SymplecticIntegrator)
    assert clone.method_name == "yoshida-4" and clone.backend == backend
    assert "yoshida-4" in clone.describe()
    a, b = water8.context(ig), water8.context(clone)
    ig.step(20)
    clone.step(20)
    np.testing.assert_array_equal(_positions(a), _positions(b))
    assert clone.steps_taken == 20


def test_deserialize_gives_the_class_back(water8):
    ig = SymplecticIntegrator(0.002, "gauss-2", backend="custom")
    back = deserialize(mm.XmlSerializer.serialize(ig))
    assert isinstance(back, CustomSymplecticIntegrator) and back.method_name == "gauss-2"
    with pytest.raises(TypeError, match="not an integrator of openmm_symprk"):
        restore(mm.VerletIntegrator(0.001))


@pytest.mark.skipif(not plugin.available(), reason="native plugin unavailable")
def test_plain_xml_deserialize_of_a_native_integrator_works_once_the_package_is_imported(water8):
    ig = SymplecticIntegrator(0.002, "verlet", system=water8.system, backend="native")
    plain = mm.XmlSerializer.deserialize(mm.XmlSerializer.serialize(ig))  # the proxy is registered on import
    back = restore(plain)
    assert isinstance(back, NativeSymplecticIntegrator) and back.getExpectedNumParticles() == 24


# -- 10. the blow-up threshold --------------------------------------------------------------------------------------------
@pytest.mark.parametrize("backend", BACKENDS)
def test_fast_but_finite_velocities_are_not_a_blow_up_unless_asked(backend):
    """A start with an overlap flings atoms at ~1e6 nm/ps, and the run relaxes (OpenMM's VerletIntegrator survives it):
    only NaN or infinity counts by default; max_speed= makes a finite speed count too."""
    system = mm.System()
    for _ in range(2):
        system.addParticle(1.0)
    repulsion = mm.CustomBondForce("1e-6/r^12")
    repulsion.addBond(0, 1)
    system.addForce(repulsion)
    for max_speed, expect in ((None, None), (1e5, SimulationBlowUpError)):
        ig = SymplecticIntegrator(1e-6, "verlet", system=system, backend=backend, max_speed=max_speed)
        ctx = mm.Context(system, ig, mm.Platform.getPlatformByName("Reference"))
        ctx.setPositions([mm.Vec3(0, 0, 0), mm.Vec3(0.02, 0, 0)])
        if expect is None:
            ig.step(200)
            assert np.abs(_velocities(ctx)).max() > 1e5
        else:
            with pytest.raises(expect, match="faster than 100000 nm/ps"):
                ig.step(200)


# -- 7. constrained steps on OpenCL at OpenMM's default constraint tolerance -------------------------------------------------
def _constrained_chain(n=10):
    """A chain of n carbons held by n-1 distance constraints (CCMA), with angle terms: the solver stops at its
    tolerance, so what a method does with the residual shows."""
    from openmm_symprk.systems.prepare import maxwell_boltzmann

    system = mm.System()
    pos = np.array([[0.15 * i, 0.05 * (i % 2), 0.0] for i in range(n)])
    angles = mm.HarmonicAngleForce()
    for i in range(n):
        system.addParticle(12.0)
    for i in range(n - 1):
        system.addConstraint(i, i + 1, float(np.linalg.norm(pos[i + 1] - pos[i])))
    for i in range(n - 2):
        angles.addAngle(i, i + 1, i + 2, 2.0, 300.0)
    system.addForce(angles)
    return system, pos, maxwell_boltzmann(system, pos, 300.0, 3)


@needs_opencl
def test_every_splitting_keeps_constraints_on_opencl_at_the_default_tolerance():
    """With tolerance 1e-5 the constraint solver leaves residuals of that size; a drift after a much smaller one
    (pefrl: 0.775 after -0.066) used to amplify them from drift to drift, and the energy wandered 15-25x more
    than Verlet's (pefrl, mclachlan-sb3a4, sofroniou-spaletta-10).  Every splitting now stays within 2x of
    Verlet's energy error at the same tolerance, step and length on OpenCL (PoCL), within 4x on CUDA (H100, double:
    position-verlet and bcss-2, whose steps hold two constrained drifts, measured 3.0x and 2.8x)."""
    from openmm_symprk import catalogue

    system, pos, vel = _constrained_chain()
    errors = {}
    for m in catalogue.splittings():
        if m.order < 2:
            continue
        ig = SymplecticIntegrator(0.1 * unit.femtoseconds, m.name, system=system)
        assert ig.getConstraintTolerance() == 1e-5
        ctx = mm.Context(system, ig, mm.Platform.getPlatformByName(COMMON), {"Precision": "double"})
        ctx.setPositions(pos)
        ctx.setVelocities(vel)
        energies = []
        for _ in range(5):
            ig.step(100)
            st = ctx.getState(getEnergy=True)
            energies.append((st.getKineticEnergy() + st.getPotentialEnergy()).value_in_unit(unit.kilojoule_per_mole))
        errors[m.name] = max(energies) - min(energies)
        del ctx
    bound = 4 if COMMON == "CUDA" else 2
    worst = {k: v for k, v in errors.items() if v > bound * errors["verlet"]}
    assert not worst, (errors["verlet"], worst)
