"""The thermostat at the edges OpenMM's own thermostat tests and unusual input reach (issue 27): a reinitialized
Context, copies of a used integrator, clusters far from the origin, systems without peculiar kinetic energy, linear
molecules, checkpoints with another temperature.  Each test failed before its fix."""
import copy
from dataclasses import replace
import pickle
import warnings

import numpy as np
import openmm as mm
import openmm.unit as unit
import pytest

from helpers import BACKENDS, COMMON, context, native_skip_reason
from openmm_symprk import SymplecticIntegrator, plugin
from openmm_symprk.integrators import deserialize
from openmm_symprk.systems.scenes import water_cluster

REF = "Reference"
pytestmark = pytest.mark.filterwarnings("ignore::openmm_symprk.systems.checks.ConservationWarning")


#: the linear-system tests on native also run the Common (device) kernel, in double precision, where it is built
LINEAR_CASES = ["custom", pytest.param("native", marks=pytest.mark.skipif(native_skip_reason() is not None,
                                                                          reason=str(native_skip_reason()))),
                pytest.param("native-opencl", marks=pytest.mark.skipif(
                    native_skip_reason() is not None or COMMON not in plugin.platforms(),
                    reason=f"no native {COMMON} kernel here"))]


def _linear_case(case):
    """(backend, platform, properties) of a LINEAR_CASES entry."""
    if case == "native-opencl":
        return "native", COMMON, {"Precision": "double"}
    return case, REF, {}


def velocities(ctx):
    return np.asarray(ctx.getState(getVelocities=True).getVelocities(asNumpy=True)
                      .value_in_unit(unit.nanometer / unit.picosecond))


@pytest.fixture(scope="module")
def cluster():
    return water_cluster(8)


# -- 1: a reinitialized Context is thermostatted from its first step --------------------------------------------------
@pytest.mark.parametrize("backend", BACKENDS)
def test_reinitialize_thermostats_from_the_first_step(backend, cluster):
    """OpenMM's testRandomSeed, ported: after Context.reinitialize() and the same positions and velocities, the
    same integrator (same seed) repeats its first run; before the fix the whole next step(n) ran without the
    thermostat (no heat exchanged)."""
    ig = SymplecticIntegrator(0.002, "verlet", system=cluster.system, backend=backend, temperature=300,
                              collision_time=0.02, random_seed=1)
    ctx = context(cluster.system, ig, cluster.positions, cluster.velocities)
    ig.step(20)
    first, heat_first = velocities(ctx), ig.computeHeatBathEnergy()
    ctx.reinitialize()
    ctx.setPositions(cluster.positions)
    ctx.setVelocities(cluster.velocities)
    with warnings.catch_warnings():
        warnings.simplefilter("error", RuntimeWarning)
        ig.step(1)
        heat_after_one = ig.computeHeatBathEnergy()
        ig.step(19)
    assert heat_after_one != heat_first  # the first step after reinitialize ran an event
    assert velocities(ctx).tobytes() == first.tobytes()  # ... and the run repeats the first one
    # a Context reinitialized without its state starts a new run: the heat-bath energy from 0, on both backends
    assert ig.computeHeatBathEnergy() == heat_first


# -- 4: copies of a used integrator carry no run-time state -----------------------------------------------------------
@pytest.mark.parametrize("backend", BACKENDS)
@pytest.mark.parametrize("how", ["xml", "pickle", "deepcopy"])
def test_copy_of_a_used_integrator_runs_as_a_fresh_one(backend, cluster, how):
    def make():
        return SymplecticIntegrator(0.002, "omelyan-2", system=cluster.system, backend=backend, temperature=320,
                                    collision_time=0.05, random_seed=21)

    used = make()
    ctx = context(cluster.system, used, cluster.positions, cluster.velocities)
    used.step(15)
    assert used.computeHeatBathEnergy() != 0 * unit.kilojoule_per_mole
    copied = {"xml": lambda: deserialize(mm.XmlSerializer.serialize(used)),
              "pickle": lambda: pickle.loads(pickle.dumps(used)),
              "deepcopy": lambda: copy.deepcopy(used)}[how]()
    del ctx
    assert copied.computeHeatBathEnergy() == 0 * unit.kilojoule_per_mole
    runs = []
    for integrator in (make(), copied):
        c = context(cluster.system, integrator, cluster.positions, cluster.velocities)
        assert integrator.steps_taken == 0
        integrator.step(12)
        runs.append((velocities(c).tobytes(), integrator.computeHeatBathEnergy(), integrator.steps_taken))
        del c
    assert runs[0] == runs[1]


# -- 3: angular momentum far from the origin ----------------------------------------------------------------------
@pytest.mark.parametrize("backend", BACKENDS)
@pytest.mark.parametrize("distance", [1e4, 1e5])
def test_angular_momentum_kept_far_from_the_origin(backend, distance):
    """An 8-water cluster moved ``distance`` nm from the origin, 1000 steps: with the thermostat, L about the centre
    of mass (the frame-independent part) changes at most 3 times as much as in the NVE run from the same state, which
    loses it only through the positions' own precision there (measured: 5e-9 at 1e4 nm, 5e-8 at 1e5 nm, relative;
    with the thermostat 1.1e-8 and 9e-8).  Before the fix the thermostat's moments about the origin lost 1e-6
    (1e4 nm) and 1.7e-4 (1e5 nm)."""
    scene = water_cluster(8)
    x = np.asarray(scene.positions) + distance * np.array([1.0, 0.6, -0.8])
    m = np.array([scene.system.getParticleMass(i).value_in_unit(unit.dalton)
                  for i in range(scene.system.getNumParticles())])
    change = {}
    # the ends placement (the bound of the middle one, 20x, is in test_thermostat_native_placement)
    nvt = dict(temperature=300, collision_time=0.01, random_seed=3, thermostat_position="ends")
    for kind, options in (("nve", {}), ("nvt", nvt)):
        ig = SymplecticIntegrator(0.002, "verlet", system=scene.system, backend=backend, **options)
        ctx = context(scene.system, ig, x, scene.velocities)

        def l_about_com():
            st = ctx.getState(getPositions=True, getVelocities=True)
            X = np.asarray(st.getPositions(asNumpy=True).value_in_unit(unit.nanometer))
            V = np.asarray(st.getVelocities(asNumpy=True).value_in_unit(unit.nanometer / unit.picosecond))
            R = (m[:, None] * X).sum(0) / m.sum()
            return (m[:, None] * np.cross(X - R, V)).sum(0)

        L0 = l_about_com()
        ig.step(1000)
        change[kind] = np.linalg.norm(l_about_com() - L0) / np.linalg.norm(L0)
        assert (ig.computeHeatBathEnergy() != 0 * unit.kilojoule_per_mole) == (kind == "nvt")
        del ctx
    assert change["nvt"] < 3 * change["nve"] + 1e-12, change


# -- 6: nothing to scale --------------------------------------------------------------------------------------------
def _gas(n):
    system = mm.System()
    for k in range(n):
        system.addParticle(12.0 + k)
    x = np.random.default_rng(1).uniform(0, 2, (n, 3))
    return system, x


@pytest.mark.parametrize("backend", BACKENDS)
@pytest.mark.parametrize("motion", ["at rest", "rigid translation"])
def test_no_peculiar_kinetic_energy_warns_once_and_scales_nothing(backend, motion):
    system, x = _gas(10)
    v = np.zeros_like(x) if motion == "at rest" else np.tile([0.3, -1.2, 0.7], (10, 1))
    ig = SymplecticIntegrator(0.002, "verlet", system=system, backend=backend, temperature=300, random_seed=2)
    ctx = context(system, ig, x, v)
    with pytest.warns(RuntimeWarning, match="found no peculiar kinetic energy.*setVelocitiesToTemperature"):
        ig.step(5)
    with warnings.catch_warnings():
        warnings.simplefilter("error", RuntimeWarning)
        ig.step(5)  # once
    after = velocities(ctx)
    assert np.array_equal(after, v)  # round-off not amplified: every velocity exactly as it was
    assert ig.computeHeatBathEnergy() == 0 * unit.kilojoule_per_mole
    ctx.setVelocitiesToTemperature(300, 1)
    ig.step(20)
    assert ig.computeHeatBathEnergy() != 0 * unit.kilojoule_per_mole


@pytest.mark.parametrize("backend", BACKENDS)
@pytest.mark.parametrize("position", ["ends", "middle"])
def test_a_run_started_at_rest_that_moves_does_not_warn(backend, position, cluster):
    """Only the first event of a cluster started at rest finds nothing to scale (its forces set it moving): no warning,
    on either backend (the native one warned for that single skipped event before issue 36)."""
    ig = SymplecticIntegrator(0.002, "verlet", system=cluster.system, backend=backend, temperature=300, random_seed=2,
                              thermostat_position=position)
    ctx = context(cluster.system, ig, cluster.positions, np.zeros((cluster.system.getNumParticles(), 3)))
    with warnings.catch_warnings():
        warnings.simplefilter("error", RuntimeWarning)
        ig.step(10)
    assert ig._skipped_thermostat_events() == (1 if position == "ends" else 0)
    assert ig.computeHeatBathEnergy() != 0 * unit.kilojoule_per_mole
    del ctx


# -- linear isolated systems -----------------------------------------------------------------------------------------
@pytest.mark.parametrize("case", LINEAR_CASES)
def test_isolated_diatomic_has_one_degree_of_freedom_and_keeps_l(case):
    """A harmonic diatomic in vacuum: 6 - 3 (centre of mass) - 2 (rotations of a linear system) = 1 degree of
    freedom, the vibration; its thermostat keeps P and L and samples <K_vib> = kT/2."""
    backend, platform, properties = _linear_case(case)
    system = mm.System()
    for mass in (12.0, 16.0):
        system.addParticle(mass)
    bond = mm.HarmonicBondForce()
    bond.addBond(0, 1, 0.113, 1.0e5)
    system.addForce(bond)
    ig = SymplecticIntegrator(0.0005, "verlet", system=system, backend=backend, temperature=300,
                              collision_time=0.02, random_seed=5)
    assert ig.thermostat_dof == 1
    x = np.array([[0.0, 0.0, 0.0], [0.115, 0.01, 0.0]])
    v = np.array([[0.1, 0.5, -0.2], [-0.3, -0.2, 0.4]])
    ctx = context(system, ig, x, v, platform, properties)
    m = np.array([12.0, 16.0])
    L0 = (m[:, None] * np.cross(x, v)).sum(0)
    ig.step(2000)
    st = ctx.getState(getPositions=True, getVelocities=True)
    X = np.asarray(st.getPositions(asNumpy=True)._value)
    V = np.asarray(st.getVelocities(asNumpy=True)._value)
    assert np.linalg.norm((m[:, None] * (V - v)).sum(0)) < 1e-12 * np.sum(m[:, None] * np.abs(V))
    assert np.linalg.norm((m[:, None] * np.cross(X, V)).sum(0) - L0) < 1e-9 * np.linalg.norm(L0)


# -- checkpoints keep the integrator's temperature --------------------------------------------------------------------
@pytest.mark.parametrize("backend", BACKENDS)
def test_loading_a_checkpoint_keeps_the_current_temperature(backend, cluster):
    """As OpenMM's LangevinMiddleIntegrator: the temperature is the integrator's, not the checkpoint's."""
    ig = SymplecticIntegrator(0.002, "verlet", system=cluster.system, backend=backend, temperature=300,
                              random_seed=4)
    ctx = context(cluster.system, ig, cluster.positions, cluster.velocities)
    ig.step(5)
    chk = ctx.createCheckpoint()
    ig.setTemperature(450)
    ctx.loadCheckpoint(chk)
    ig.step(1)
    assert ig.getTemperature() == 450 * unit.kelvin
    if backend == "custom":
        from openmm_symprk.integrators import thermostat_program as tp

        assert ig.getGlobalVariableByName(tp.TEMPERATURE_VAR) == 450


@pytest.mark.parametrize("case", LINEAR_CASES)
def test_linear_triatomic_keeps_p_and_l(case):
    """A flexible CO2-like triatomic, isolated, started on a line with velocities along it and a rotation about a
    perpendicular axis: it stays linear, its inertia tensor is singular, and the kept rotation (w = 2 L / tr I) keeps
    L and P through the thermostat's events.  (Its degrees of freedom count 3 rotations: the System does not say it
    is linear, docs/thermostat.md.)"""
    backend, platform, properties = _linear_case(case)
    system = mm.System()
    for mass in (16.0, 12.0, 16.0):
        system.addParticle(mass)
    bond = mm.HarmonicBondForce()
    bond.addBond(0, 1, 0.116, 5.0e5)
    bond.addBond(1, 2, 0.116, 5.0e5)
    system.addForce(bond)
    ig = SymplecticIntegrator(0.0005, "verlet", system=system, backend=backend, temperature=300,
                              collision_time=0.02, random_seed=5)
    assert ig.thermostat_dof == 9 - 3 - 3  # fixed before positions exist: 3 rotations (docs/thermostat.md)
    x = np.array([[-0.118, 0.0, 0.0], [0.0, 0.0, 0.0], [0.117, 0.0, 0.0]])
    v = np.array([[0.3, 0.2, 0.0], [-0.1, 0.0, 0.0], [-0.2, -0.2, 0.0]])  # spins about z, drifts along x
    m = np.array([16.0, 12.0, 16.0])
    ctx = context(system, ig, x, v, platform, properties)
    L0 = (m[:, None] * np.cross(x, v)).sum(0)
    ig.step(2000)
    st = ctx.getState(getPositions=True, getVelocities=True)
    X = np.asarray(st.getPositions(asNumpy=True)._value)
    V = np.asarray(st.getVelocities(asNumpy=True)._value)
    assert ig.computeHeatBathEnergy() != 0 * unit.kilojoule_per_mole
    assert np.linalg.norm((m[:, None] * (V - v)).sum(0)) < 1e-12 * np.sum(m[:, None] * np.abs(V))
    assert np.linalg.norm((m[:, None] * np.cross(X, V)).sum(0) - L0) < 1e-9 * np.linalg.norm(L0)


# -- between a reinitialize or a checkpoint and the next step both backends report the same run (issue 36) -------------
@pytest.mark.parametrize("backend", BACKENDS)
def test_reinitialized_context_reports_a_new_run_at_once(backend, cluster):
    """Before issue 36 the custom backend went on reporting the old run's heat-bath energy, kinetic energy and step
    count until the next step, and the native one kept its step count."""
    ig = SymplecticIntegrator(0.002, "verlet", system=cluster.system, backend=backend, temperature=300, random_seed=3)
    ctx = context(cluster.system, ig, cluster.positions, cluster.velocities)
    ig.step(20)
    kj = unit.kilojoule_per_mole
    assert ig.computeHeatBathEnergy() != 0 * kj and ig.steps_taken == 20
    ctx.reinitialize()
    assert ig.computeHeatBathEnergy() == 0 * kj
    assert ig.thermostat_kinetic_energy() == 0 * kj
    assert ig.steps_taken == 0
    ctx.setPositions(cluster.positions)
    ctx.setVelocities(cluster.velocities)
    ig.step(3)
    assert ig.steps_taken == 3 and ig.computeHeatBathEnergy() != 0 * kj


@pytest.mark.parametrize("backend", BACKENDS)
def test_state_and_checkpoint_right_after_reinitialize_hold_a_new_run(backend, cluster):
    """A checkpoint or a State (with integrator parameters) taken right after Context.reinitialize(), before any step,
    is a new run wherever it is loaded: heat-bath energy 0 and (a checkpoint) step count 0, on both backends.  Before,
    the custom backend's carried the old run's (its global variables outlive the reinitialize: heat bath -40 kJ/mol,
    100 steps), since it noticed the new run only through its Context, at its next step."""
    def make():
        return SymplecticIntegrator(0.002, "verlet", system=cluster.system, backend=backend, temperature=300,
                                    random_seed=3)

    kj = unit.kilojoule_per_mole
    ig = make()
    ctx = context(cluster.system, ig, cluster.positions, cluster.velocities)
    ig.step(100)
    assert ig.computeHeatBathEnergy() != 0 * kj
    ctx.reinitialize()
    ctx.setPositions(cluster.positions)
    ctx.setVelocities(cluster.velocities)
    chk = ctx.createCheckpoint()
    state = ctx.getState(getPositions=True, getVelocities=True, integratorParameters=True)
    other = make()
    octx = context(cluster.system, other, cluster.positions, cluster.velocities)
    octx.loadCheckpoint(chk)  # into a new Context, before its first step
    assert (other.computeHeatBathEnergy(), other.steps_taken) == (0 * kj, 0)
    other.step(30)
    octx.loadCheckpoint(chk)  # into a running one
    assert (other.computeHeatBathEnergy(), other.steps_taken) == (0 * kj, 0)
    other.step(30)
    assert other.computeHeatBathEnergy() != 0 * kj
    octx.setState(state)
    assert other.computeHeatBathEnergy() == 0 * kj
    third = make()
    tctx = context(cluster.system, third, cluster.positions, cluster.velocities)
    tctx.setState(state)
    assert (third.computeHeatBathEnergy(), third.steps_taken) == (0 * kj, 0)
    # and the run loaded goes on as a new run: the thermostat acts from its first step
    other.step(1)
    assert other.computeHeatBathEnergy() != 0 * kj


@pytest.mark.parametrize("backend", BACKENDS)
def test_loaded_checkpoint_reports_its_run_and_the_integrators_temperature(backend, cluster):
    """After loadCheckpoint, before any step: the checkpoint's heat-bath energy, kinetic energy at the thermostat and
    step count, and the temperature the next step will use (the integrator's).  Before issue 36 the custom backend
    read back the checkpoint's temperature, the native one the kinetic energy of the run it left."""
    ig = SymplecticIntegrator(0.002, "verlet", system=cluster.system, backend=backend, temperature=300, random_seed=3)
    ctx = context(cluster.system, ig, cluster.positions, cluster.velocities)
    ig.step(20)
    chk = ctx.createCheckpoint()
    saved = (ig.computeHeatBathEnergy(), ig.thermostat_kinetic_energy())
    ig.setTemperature(350)
    ig.step(10)
    assert (ig.computeHeatBathEnergy(), ig.thermostat_kinetic_energy()) != saved
    ctx.loadCheckpoint(chk)
    assert (ig.computeHeatBathEnergy(), ig.thermostat_kinetic_energy()) == saved
    assert ig.getTemperature() == 350 * unit.kelvin and ig.steps_taken == 20


@pytest.mark.parametrize("backend", BACKENDS)
def test_a_step_count_set_to_zero_keeps_the_run(backend, cluster):
    """Simulation.currentStep = 0 (Context.setStepCount(0)) is not a reinitialize: the heat bath and the step counter
    that places the interval's events go on, on both backends (the custom backend took it for a new run)."""
    ig = SymplecticIntegrator(0.002, "verlet", system=cluster.system, backend=backend, temperature=300, random_seed=3,
                              thermostat_interval=2)
    ctx = context(cluster.system, ig, cluster.positions, cluster.velocities)
    ig.step(5)
    before = (ig.computeHeatBathEnergy(), ig.steps_taken)
    ctx.setStepCount(0)
    assert (ig.computeHeatBathEnergy(), ig.steps_taken) == before
    ig.step(1)
    assert ig.steps_taken == 6


@pytest.mark.parametrize("backend", BACKENDS)
def test_a_pickle_of_0_2_keeps_its_thermostat(backend, cluster):
    """0.2.0 pickled the settings as the attribute ``thermostat`` (custom) or not at all (native: the plugin held
    them); such a pickle still restores an NVT integrator with its current settings."""

    ig = SymplecticIntegrator(0.002, "verlet", system=cluster.system, backend=backend, temperature=300, random_seed=3)
    ig.setTemperature(320)
    func, (cls, xml, state) = ig.__reduce__()
    old = dict(state)
    settings = old.pop("_thermostat")
    if backend == "custom":
        old["thermostat"] = settings
    back = func(cls, xml, old)
    # (the native plugin holds the placement as its events run: "auto" was resolved to verlet's middle)
    asked = settings if backend == "custom" else replace(settings, position="middle")
    assert back.thermostat == asked and back.getTemperature() == 320 * unit.kelvin
    assert back.thermostat_position == ig.thermostat_position == "middle"


# -- what computeSystemTemperature reads ----------------------------------------------------------------------------------
def _state_temperature(ctx, ig) -> float:
    """2 K_pec / (N_f R) of the Context's velocities (the kept rigid motion taken out), in K."""
    from openmm_symprk.physics.temperature import R_KJ
    from openmm_symprk.physics.velocity_rescaling import kept_velocities
    from openmm_symprk.systems.properties import masses

    st = ctx.getState(getPositions=True, getVelocities=True)
    x = st.getPositions(asNumpy=True).value_in_unit(unit.nanometer)
    v = st.getVelocities(asNumpy=True).value_in_unit(unit.nanometer / unit.picosecond)
    m = masses(ctx.getSystem())
    u = kept_velocities(x, v, m, ig.thermostat.keep_rotation)
    return float(np.sum(m[:, None] * (v - u) ** 2)) / (ig.thermostat_dof * R_KJ)


@pytest.mark.parametrize("backend", BACKENDS)
def test_system_temperature_is_the_thermostats_and_nve_has_none(backend, cluster):
    """computeSystemTemperature() is the thermostat's: 2 K'/(N_f R) of its last event, which with the default placement
    (verlet: the middle, the State holding the thermostat point's velocities) is the State's peculiar temperature up
    to the constraint correction of the half drift after the event (rigid waters: 0.3 %).  It is NaN before the first
    event; after setVelocitiesToTemperature it reads the last event's until the next step (the integrator cannot
    reach its Context: that took a scan of the Python heap before), then the new velocities'.  An NVE integrator has
    none (hasattr False), so OpenMM's StateDataReporter computes the temperature from the State, as for
    VerletIntegrator; before, it had one that needed the heap scan to find its Context."""
    import io
    import math

    import openmm.app as app

    nve = SymplecticIntegrator(0.002, "verlet", system=cluster.system, backend=backend)
    assert not hasattr(nve, "computeSystemTemperature")
    with pytest.raises(AttributeError, match="runs NVE.*StateDataReporter does so itself"):
        nve.computeSystemTemperature()
    sim = app.Simulation(cluster.topology, cluster.system, nve, mm.Platform.getPlatformByName(REF))
    sim.context.setPositions(cluster.positions)
    sim.context.setVelocities(cluster.velocities)
    out = io.StringIO()
    sim.reporters.append(app.StateDataReporter(out, 5, temperature=True))
    sim.step(10)
    assert all(float(line.split(",")[0]) > 0 for line in out.getvalue().splitlines()[1:])

    ig = SymplecticIntegrator(0.002, "verlet", system=cluster.system, backend=backend, temperature=300, random_seed=4)
    assert ig.thermostat_position == "middle"
    ctx = context(cluster.system, ig, cluster.positions, cluster.velocities)
    assert math.isnan(ig.computeSystemTemperature().value_in_unit(unit.kelvin))
    ig.step(20)
    before = ig.computeSystemTemperature().value_in_unit(unit.kelvin)
    assert before == pytest.approx(_state_temperature(ctx, ig), rel=3e-3)
    ctx.setVelocitiesToTemperature(600 * unit.kelvin, 5)
    assert ig.computeSystemTemperature().value_in_unit(unit.kelvin) == before  # the last event's, as documented
    ig.step(1)
    after = ig.computeSystemTemperature().value_in_unit(unit.kelvin)
    assert after > before + 50 and after == pytest.approx(_state_temperature(ctx, ig), rel=3e-3)


@pytest.mark.parametrize("backend", BACKENDS)
def test_no_heap_scan_with_simulation_checkpoints_and_copies(backend, cluster, monkeypatch):
    """The integrators never look for their Context in the Python heap (the custom backend did, with gc.get_objects, to
    notice a reinitialized Context and to compute temperatures): with the heap scan made to fail, an NVT run in an
    app.Simulation, its reinitialize, checkpoint and State, and its pickle, deepcopy and XML copies all run and report
    as before."""
    import gc

    import openmm.app as app

    def no_scan(*args, **kwargs):
        raise AssertionError("the Python heap was scanned")

    monkeypatch.setattr(gc, "get_objects", no_scan)
    kj = unit.kilojoule_per_mole
    ig = SymplecticIntegrator(0.002, "verlet", system=cluster.system, backend=backend, temperature=300, random_seed=5,
                              exact_momentum=True)
    sim = app.Simulation(cluster.topology, cluster.system, ig, mm.Platform.getPlatformByName(REF))
    sim.context.setPositions(cluster.positions)
    sim.context.setVelocities(cluster.velocities)
    sim.step(10)
    assert ig.steps_taken == 10 and ig.computeHeatBathEnergy() != 0 * kj
    assert ig.computeSystemTemperature().value_in_unit(unit.kelvin) > 0
    chk = sim.context.createCheckpoint()
    sim.step(5)
    sim.context.loadCheckpoint(chk)
    assert ig.steps_taken == 10
    sim.context.reinitialize()
    assert (ig.computeHeatBathEnergy(), ig.steps_taken) == (0 * kj, 0)
    sim.context.setPositions(cluster.positions)
    sim.context.setVelocities(cluster.velocities)
    sim.step(3)
    assert ig.steps_taken == 3 and ig.computeHeatBathEnergy() != 0 * kj
    for copied in (pickle.loads(pickle.dumps(ig)), copy.deepcopy(ig), deserialize(mm.XmlSerializer.serialize(ig))):
        ctx = context(cluster.system, copied, cluster.positions, cluster.velocities)
        copied.step(4)
        assert copied.steps_taken == 4 and copied.computeHeatBathEnergy() != 0 * kj
        del ctx
