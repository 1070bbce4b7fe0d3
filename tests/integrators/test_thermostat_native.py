"""The thermostat of the native plugin (stochastic velocity rescaling, platforms/*: SymPRKThermostat and the
Reference/CPU and Common kernels), on Reference, CPU and OpenCL (PoCL) in double, mixed and single precision.

* the factor the plugin computes is openmm_symprk.physics.velocity_rescaling.rescaling_factor, bit for bit;
* one event rescales the peculiar velocities about the kept field (centre-of-mass velocity and rigid rotation)
  by one factor, and the heat-bath energy is minus the kinetic energy it added;
* P to round-off in a periodic box, L to round-off for an isolated cluster;
* the kinetic energy of an ideal gas is Gamma(dof/2, kT) (KS test, mean and variance), <T> of a water box;
* checkpoints continue bit for bit, XML keeps the settings, no thermostat is the NVE program.

Skipped as a whole, with the loader's reason, when the plugin is not built.
"""
import math
import warnings

import numpy as np
import openmm as mm
import openmm.unit as unit
import pytest

from helpers import COMMON, positions_velocities
from openmm_symprk import SymplecticIntegrator, plugin
from openmm_symprk.integrators import NativeSymplecticIntegrator as N
from openmm_symprk.integrators import deserialize
from openmm_symprk.physics.temperature import R_KJ
from openmm_symprk.physics.velocity_rescaling import kept_velocities, rescaling_factor
from openmm_symprk.stats.timeseries import block_stats, series_stats

pytestmark = pytest.mark.skipif(not plugin.available(), reason=f"native plugin unavailable: {plugin.unavailable_reason()}")

OPENCL = COMMON in plugin.platforms()
needs_opencl = pytest.mark.skipif(not OPENCL, reason=f"no native {COMMON} kernel here ({COMMON} platform or its build missing)")
#: (platform, properties, relative tolerance of one event's arithmetic)
PLATFORMS = [("Reference", {}, 1e-12), ("CPU", {}, 1e-12),
             pytest.param(COMMON, {"Precision": "double"}, 1e-12, marks=needs_opencl, id="OpenCL-double"),
             pytest.param(COMMON, {"Precision": "mixed"}, 1e-9, marks=needs_opencl, id="OpenCL-mixed"),
             pytest.param(COMMON, {"Precision": "single"}, 3e-6, marks=needs_opencl, id="OpenCL-single")]


def _platform(name):
    return mm.Platform.getPlatformByName(name)


def _ideal_gas(n=20, seed=3, massless=True):
    """n free particles of mixed masses in vacuum (isolated: the rotation is kept), plus one massless one."""
    rng = np.random.default_rng(seed)
    system = mm.System()
    masses = rng.choice([1.008, 12.0, 15.999], size=n)
    for m in masses:
        system.addParticle(float(m))
    if massless:
        system.addParticle(0.0)
        masses = np.append(masses, 0.0)
    x = rng.uniform(-0.8, 0.8, size=(len(masses), 3))
    v = rng.normal(size=(len(masses), 3)) * np.sqrt(R_KJ * 300 / np.where(masses > 0, masses, 1.0))[:, None]
    v += np.array([0.3, -0.2, 0.1])  # a centre-of-mass velocity to keep
    v += np.cross([0.0, 1.5, -2.0], x)  # and a rotation
    return system, masses, x, v


def _peculiar_kinetic(x, v, m, keep_rotation=True):
    u = kept_velocities(x[m > 0], v[m > 0], m[m > 0], keep_rotation)
    return 0.5 * float(np.sum(m[m > 0, None] * (v[m > 0] - u) ** 2)), u


def _momenta(x, v, m):
    return (m[:, None] * v).sum(axis=0), (m[:, None] * np.cross(x, v)).sum(axis=0)


# -- the factor --------------------------------------------------------------------------------------------------
def test_factor_is_the_python_expression_bit_for_bit():
    """SymPRKIntegrator.computeRescalingFactor (what every kernel calls) against rescaling_factor, for draws
    covering both signs of alpha, c near 0 and 1, one degree of freedom and zero kinetic energy."""
    swig = plugin.swig_module()
    rng = np.random.default_rng(11)
    cases = [(0.0, 10.0, 5, 0.5, 0.3, 2.0), (5.0, 10.0, 1, 0.9, -0.4, 0.0), (1e-3, 100.0, 30, 0.01, -3.0, 25.0),
             (3.0, 3.0, 7, 1.0, 1.0, 6.0)]
    for _ in range(500):
        dof = int(rng.integers(1, 5000))
        cases.append((float(rng.gamma(dof / 2)), float(dof / 2 * rng.uniform(0.5, 2)), dof, float(rng.uniform(0, 1)),
                      float(rng.normal() * 3), float(2 * rng.gamma((dof - 1) / 2)) if dof > 1 else 0.0))
    negative = 0
    for case in cases:
        alpha, new = swig.SymPRKIntegrator.computeRescalingFactor(*case)
        assert (alpha, new) == rescaling_factor(*case), case
        negative += alpha < 0
    assert negative > 0  # the reversed branch was exercised


# -- one event ---------------------------------------------------------------------------------------------------
@pytest.mark.parametrize("platform,props,tol", PLATFORMS)
def test_one_event_rescales_peculiar_velocities_by_one_factor(platform, props, tol):
    """Free particles, thermostat every 2 steps: step 1 is an event before a free flight, so the velocities after
    it are the event's.  They must be u + alpha (v - u) for the kept field u of the initial state (centre-of-mass
    velocity and rigid rotation), massless particles untouched, P and L unchanged, and the heat-bath energy
    -(K' - K_pec) = -(alpha^2 - 1) K_pec; over more steps K + heat-bath energy stays K(0)."""
    system, m, x, v = _ideal_gas(massless=False)
    ig = N(0.002, "verlet", system=system, temperature=300, collision_time=0.01, thermostat_interval=2, random_seed=7, thermostat_position="ends")
    assert ig.thermostat_dof == 3 * 20 - 6 and ig.thermostat.keep_rotation
    ctx = mm.Context(system, ig, _platform(platform), props)
    ctx.setPositions(x)
    ctx.setVelocities(v)
    x0, v0 = positions_velocities(ctx)  # as the platform stores them
    ig.step(1)
    _, v1 = positions_velocities(ctx)
    k_pec, u = _peculiar_kinetic(x0, v0, m)
    w = m[m > 0, None]
    d0, d1 = v0[m > 0] - u, v1[m > 0] - u
    alpha = float(np.sum(w * d0 * d1) / np.sum(w * d0 * d0))
    scale = float(np.abs(v0).max())
    assert abs(alpha - 1) > 1e-3  # the event did something
    assert np.abs(d1 - alpha * d0).max() <= 10 * tol * scale
    bath = ig.computeHeatBathEnergy().value_in_unit(unit.kilojoule_per_mole)
    assert bath == pytest.approx(-(alpha ** 2 - 1) * k_pec, rel=10 * tol, abs=10 * tol * k_pec)
    p0, l0 = _momenta(x0, v0, m)
    p1, l1 = _momenta(x0, v1, m)
    pscale = float(np.sum(m[:, None] * np.abs(v0)))
    assert np.linalg.norm(p1 - p0) <= 10 * tol * pscale
    assert np.linalg.norm(l1 - l0) <= 10 * tol * np.linalg.norm(l0)
    # K changes only through the events (no forces): K + heat-bath energy is conserved
    k0 = 0.5 * float(np.sum(m[:, None] * v0 ** 2))
    ig.step(9)
    _, v10 = positions_velocities(ctx)
    k10 = 0.5 * float(np.sum(m[:, None] * v10 ** 2))
    bath = ig.computeHeatBathEnergy().value_in_unit(unit.kilojoule_per_mole)
    assert abs(k10 + bath - k0) <= 20 * tol * k0


def test_massless_particles_are_untouched():
    """A massless particle (frozen: the System is then not isolated, so only the centre-of-mass velocity is kept)
    neither counts in the sums nor moves."""
    system, m, x, v = _ideal_gas(n=10)
    with warnings.catch_warnings():  # NVT: the frozen particle breaks no conservation the run asked for, so no warning
        warnings.simplefilter("error")
        ig = N(0.002, "verlet", system=system, temperature=300, collision_time=0.01, random_seed=7, thermostat_position="ends")
    assert ig.thermostat_dof == 3 * 10 - 3 and not ig.thermostat.keep_rotation
    ctx = mm.Context(system, ig, _platform("Reference"))
    ctx.setPositions(x)
    ctx.setVelocities(v)
    x0, v0 = positions_velocities(ctx)
    ig.step(3)
    x1, v1 = positions_velocities(ctx)
    np.testing.assert_array_equal(v1[m == 0], v0[m == 0])
    np.testing.assert_array_equal(x1[m == 0], x0[m == 0])
    p0, p1 = (m[:, None] * v0).sum(axis=0), (m[:, None] * v1).sum(axis=0)
    assert np.linalg.norm(p1 - p0) <= 1e-13 * float(np.sum(m[:, None] * np.abs(v0)))
    assert not np.allclose(v1[m > 0], v0[m > 0])


# -- momenta -----------------------------------------------------------------------------------------------------
def _cutoff_water_box():
    """A periodic box of 64 rigid waters with a pairwise cutoff (reaction field): its forces sum to zero to
    round-off, so P is conserved to round-off by the NVE step and any change is the thermostat's."""
    from openmm_symprk.systems.scenes import water_box

    system, _, x = water_box(n_waters=64, cutoff_nm=0.55)
    for f in system.getForces():
        if isinstance(f, mm.NonbondedForce):
            f.setNonbondedMethod(mm.NonbondedForce.CutoffPeriodic)
    m = np.array([system.getParticleMass(i).value_in_unit(unit.dalton) for i in range(system.getNumParticles())])
    return system, x, m


@pytest.mark.parametrize("platform,props,bound", [
    ("Reference", {}, 1e-13),
    pytest.param(COMMON, {"Precision": "double"}, 1e-12, marks=needs_opencl, id="OpenCL-double")])
def test_momentum_to_round_off_in_a_periodic_box(platform, props, bound):
    """Double precision forces (OpenCL sums them in 64-bit fixed point: ~2e-13 of sum m|v| over the run; on CPU
    the single-precision forces alone move P by ~1e-8 of sum m|v| per step;
    the events there are checked on free particles above)."""
    system, x, m = _cutoff_water_box()
    ig = N(2 * unit.femtoseconds, "verlet", system=system, temperature=300, collision_time=0.02, random_seed=5, thermostat_position="ends")
    assert not ig.thermostat.keep_rotation  # periodic: only the centre-of-mass velocity is kept
    ctx = mm.Context(system, ig, _platform(platform), props)
    ctx.setPositions(x)
    ctx.setVelocitiesToTemperature(250, 1)
    st = ctx.getState(getVelocities=True)
    v = st.getVelocities(asNumpy=True)._value + np.array([0.2, -0.1, 0.05])  # a net momentum to keep
    ctx.setVelocities(v)
    ctx.applyVelocityConstraints(1e-10)
    _, v0 = positions_velocities(ctx)
    ig.step(60)
    _, v1 = positions_velocities(ctx)
    p0, p1 = (m[:, None] * v0).sum(axis=0), (m[:, None] * v1).sum(axis=0)
    assert np.linalg.norm(p1 - p0) <= bound * float(np.sum(m[:, None] * np.abs(v0)))
    assert ig.computeHeatBathEnergy().value_in_unit(unit.kilojoule_per_mole) != 0


def test_npt_with_a_monte_carlo_barostat_keeps_momentum():
    """The barostat moves the box in updateContextState, before the step's first event: the volume changes and
    the thermostat still keeps P to round-off (pairwise forces on Reference)."""
    system, x, m = _cutoff_water_box()
    system.addForce(mm.MonteCarloBarostat(1 * unit.bar, 300 * unit.kelvin, 5))
    ig = N(2 * unit.femtoseconds, "verlet", system=system, temperature=300, random_seed=8, thermostat_position="ends")
    ctx = mm.Context(system, ig, _platform("Reference"))
    ctx.setPositions(x)
    ctx.setVelocitiesToTemperature(300, 3)
    _, v0 = positions_velocities(ctx)
    volume = ctx.getState().getPeriodicBoxVolume()
    ig.step(150)
    _, v1 = positions_velocities(ctx)
    assert ctx.getState().getPeriodicBoxVolume() != volume
    p0, p1 = (m[:, None] * v0).sum(axis=0), (m[:, None] * v1).sum(axis=0)
    assert np.linalg.norm(p1 - p0) <= 1e-13 * float(np.sum(m[:, None] * np.abs(v0)))


@pytest.mark.parametrize("platform,props,exact,bound", [
    ("Reference", {}, False, 1e-11), ("CPU", {}, True, 1e-11),
    pytest.param(COMMON, {"Precision": "double"}, False, 1e-11, marks=needs_opencl, id="OpenCL-double"),
    pytest.param(COMMON, {"Precision": "mixed"}, True, 1e-10, marks=needs_opencl, id="OpenCL-mixed-exact"),
    pytest.param(COMMON, {"Precision": "single"}, True, 1e-5, marks=needs_opencl, id="OpenCL-single-exact")])
@pytest.mark.parametrize("position", ["ends", "middle"])
def test_angular_momentum_to_round_off_for_an_isolated_cluster(platform, props, exact, bound, position, water8):
    """Both placements (the middle one inside omelyan-2's central kick) on every platform and precision."""
    m = water8.masses()
    ig = N(2 * unit.femtoseconds, "omelyan-2", system=water8.system, temperature=300, collision_time=0.02,
           random_seed=9, exact_momentum=exact, thermostat_position=position)
    assert ig.thermostat.keep_rotation
    ctx = water8.context(ig, platform, props)
    x0, v0 = positions_velocities(ctx)
    p0, l0 = _momenta(x0, v0, m)
    ig.step(100)
    x1, v1 = positions_velocities(ctx)
    p1, l1 = _momenta(x1, v1, m)
    assert np.linalg.norm(l1 - l0) <= bound * np.linalg.norm(l0)
    assert np.linalg.norm(p1 - p0) <= bound * float(np.sum(m[:, None] * np.abs(v0)))
    assert abs(ig.computeHeatBathEnergy().value_in_unit(unit.kilojoule_per_mole)) > 1e-3


# -- the canonical distribution -------------------------------------------------------------------------------------
def _ideal_gas_kinetic_samples(platform, props, samples, seed=21):
    """K_pec after every step of a free gas thermostatted with tau << the interval (nearly independent draws)."""
    system, m, x, v = _ideal_gas(n=16, seed=seed, massless=False)
    ig = N(0.01, "verlet", system=system, temperature=250, collision_time=0.001, random_seed=seed, thermostat_position="ends")
    ctx = mm.Context(system, ig, _platform(platform), props)
    ctx.setPositions(x)
    ctx.setVelocities(v)
    out = []
    for _ in range(samples):
        ig.step(1)
        xs, vs = positions_velocities(ctx)
        out.append(_peculiar_kinetic(xs, vs, m)[0])
    return np.array(out), ig.thermostat_dof, 250 * R_KJ


@pytest.mark.parametrize("platform,props,samples", [
    ("Reference", {}, 3000),
    pytest.param(COMMON, {"Precision": "mixed"}, 1000, marks=needs_opencl, id="OpenCL-mixed")])
def test_ideal_gas_kinetic_energy_is_gamma_distributed(platform, props, samples):
    """For free particles the peculiar kinetic energy is exactly Gamma(dof/2, kT) in the canonical ensemble
    (dof = 3N - 6: centre-of-mass velocity and rotation kept): KS test, mean and variance within 3 SE."""
    stats = pytest.importorskip("scipy.stats")
    k, dof, kt = _ideal_gas_kinetic_samples(platform, props, samples)
    assert dof == 3 * 16 - 6
    assert stats.kstest(k, stats.gamma(dof / 2, scale=kt).cdf).pvalue > 1e-3
    mean, var = dof * kt / 2, dof * kt * kt / 2
    s = series_stats(k)
    assert abs(s.mean - mean) <= 3 * s.se
    var_se = math.sqrt((np.mean((k - k.mean()) ** 4) - k.var() ** 2) / len(k)) * math.sqrt(s.g)
    assert abs(k.var(ddof=1) - var) <= 3 * var_se


def test_water_box_mean_temperature(tmp_path):
    """<T> of the thermostatted degrees of freedom within 4 standard errors of the target: 64 rigid waters, PME,
    CPU, 12 ps sampled every 20 fs, the error from 24 blocks of 0.5 ps (K's autocorrelation oscillates and then
    has a slow tail of a few collision times, which the statistical inefficiency summed to its first zero misses).
    4, not 3, standard errors: the CPU platform does not repeat a run bit for bit (PME), so the seed does not fix
    this test's outcome; a correct thermostat fails it about once in 2000 runs (Student's t, 23 degrees of
    freedom), one whose T is 4 % off (about 6 standard errors) nearly always."""
    from openmm_symprk.systems.scenes import water_box

    system, _, x = water_box(n_waters=64, cutoff_nm=0.55)
    m = np.array([system.getParticleMass(i).value_in_unit(unit.dalton) for i in range(system.getNumParticles())])
    ig = N(2 * unit.femtoseconds, "omelyan-2", system=system, temperature=320, collision_time=0.05, random_seed=3, thermostat_position="ends")
    dof = ig.getThermostatDegreesOfFreedom()
    assert dof == 3 * 192 - 192 - 3
    ctx = mm.Context(system, ig, _platform("CPU"), {"Threads": "1"})
    ctx.setPositions(x)
    mm.LocalEnergyMinimizer.minimize(ctx, 10.0, 200)
    ctx.setVelocitiesToTemperature(320, 2)
    ig.step(300)
    temps = []
    for _ in range(600):
        ig.step(10)
        _, v = positions_velocities(ctx)
        pec = v - (m[:, None] * v).sum(axis=0) / m.sum()
        temps.append(float(np.sum(m[:, None] * pec ** 2)) / (dof * R_KJ))
    s = block_stats(temps, 24)
    assert abs(s.mean - 320) <= 4 * s.se, (s.mean, s.se)
    assert s.se < 2.5  # the test has power: under 1 % of the target (sd of T for these 381 DOF: 23 K)


# -- checkpoints, XML, the NVE program ----------------------------------------------------------------------------
@pytest.mark.parametrize("platform,props", [
    ("Reference", {}), pytest.param(COMMON, {"Precision": "double"}, marks=needs_opencl, id="OpenCL-double")])
def test_checkpoint_continues_bit_for_bit(platform, props, water8):
    """The heat-bath energy and the random state are in the checkpoint; the interval's phase is the step count.
    (Bit for bit on OpenCL too here: its fixed-point force sums are deterministic.)"""
    def integrator():
        return N(2 * unit.femtoseconds, "yoshida-4", system=water8.system, temperature=300, thermostat_interval=3,
                 random_seed=17, thermostat_position="ends")

    ig = integrator()
    ctx = water8.context(ig, platform, props)
    ig.step(25)
    chk = ctx.createCheckpoint()
    ig.step(40)
    straight, bath = positions_velocities(ctx), ig.computeHeatBathEnergy()
    ctx.loadCheckpoint(chk)
    ig.step(40)
    again = positions_velocities(ctx), ig.computeHeatBathEnergy()
    ig2 = integrator()
    ig2.setRandomNumberSeed(1)  # the checkpoint's random state wins over the seed
    ctx2 = mm.Context(water8.system, ig2, _platform(platform), props)
    ctx2.loadCheckpoint(chk)
    ig2.step(40)
    fresh = positions_velocities(ctx2), ig2.computeHeatBathEnergy()
    for (x, v), b in (again, fresh):
        np.testing.assert_array_equal(straight[0], x)
        np.testing.assert_array_equal(straight[1], v)
        assert b == bath
    # a checkpoint of the NVE program is refused by the thermostatted one (another program signature)
    nve = N(2 * unit.femtoseconds, "yoshida-4", system=water8.system)
    ctx3 = water8.context(nve, platform, props)
    with pytest.raises(mm.OpenMMException, match="another program.*the ensemble.*this integrator runs NVT.*saveState"):
        ctx2.loadCheckpoint(ctx3.createCheckpoint())


def test_xml_pickle_and_restore_keep_the_thermostat(water8):
    import copy
    import pickle

    ig = N(1.5 * unit.femtoseconds, "omelyan-2", system=water8.system, temperature=280 * unit.kelvin,
           collision_time=0.2 * unit.picoseconds, thermostat_interval=4, random_seed=99, thermostat_position="ends")
    xml = mm.XmlSerializer.serialize(ig)
    assert "<Thermostat" in xml and 'randomSeed="99"' in xml
    for back in (deserialize(xml), pickle.loads(pickle.dumps(ig)), copy.deepcopy(ig)):
        assert type(back) is N
        assert back.thermostat == ig.thermostat
        assert back.getTemperature() == 280 * unit.kelvin and back.getCollisionTime() == 0.2 * unit.picoseconds
        assert back.getThermostatInterval() == 4 and back.getRandomNumberSeed() == 99
        assert back.getProgramSignature() == ig.getProgramSignature()
        assert "stochastic velocity rescaling at 280 K" in back.describe()
    runs = []
    for integrator in (ig, deserialize(xml)):
        ctx = water8.context(integrator)
        integrator.step(20)
        runs.append(positions_velocities(ctx))
        del ctx
    np.testing.assert_array_equal(runs[0][0], runs[1][0])
    np.testing.assert_array_equal(runs[0][1], runs[1][1])


def test_without_temperature_the_program_is_the_nve_one(water8, morse):
    """No thermostat: no Thermostat node in the XML, the same signature as before the option existed (the
    thermostat enters it only when present), and the trajectory of the CustomIntegrator NVE program bit for bit."""
    for scene in (water8, morse):
        ig = N(1 * unit.femtoseconds, "yoshida-4", system=scene.system)
        assert not ig.hasThermostat() and ig.thermostat is None and ig.thermostat_dof is None
        assert "<Thermostat" not in mm.XmlSerializer.serialize(ig) and "thermostat" not in ig.describe()
        warm = N(1 * unit.femtoseconds, "yoshida-4", system=scene.system, temperature=300, thermostat_position="ends")
        assert warm.getProgramSignature() != ig.getProgramSignature()
        ctx = scene.context(ig)
        ig.step(30)
        a = positions_velocities(ctx)
        custom = SymplecticIntegrator(1 * unit.femtoseconds, "yoshida-4", system=scene.system, backend="custom")
        ctx2 = scene.context(custom)
        custom.step(30)
        b = positions_velocities(ctx2)
        np.testing.assert_array_equal(a[0], b[0])
        np.testing.assert_array_equal(a[1], b[1])
        assert ig.computeHeatBathEnergy() == 0 * unit.kilojoule_per_mole


# -- accessors and errors -------------------------------------------------------------------------------------------
def test_temperature_changes_mid_run_and_the_rest_is_refused_clearly(water8):
    ig = N(2 * unit.femtoseconds, "verlet", system=water8.system, temperature=300, random_seed=4, thermostat_position="ends")
    ig.setCollisionTime(0.05 * unit.picoseconds)  # before the Context: allowed
    assert ig.getCollisionTime() == 0.05 * unit.picoseconds
    ctx = water8.context(ig)
    ig.step(5)
    ig.setTemperature(350 * unit.kelvin)
    assert ig.getTemperature() == 350 * unit.kelvin and ig.getThermostatTemperature() == 350
    ig.step(5)
    with pytest.raises(ValueError, match="collision time .*0.05 ps to 0.2 ps"):
        ig.setCollisionTime(0.2)
    with pytest.raises(ValueError, match="temperature"):
        ig.setTemperature(-5 * unit.kelvin)
    del ctx
    swig = plugin.swig_module()
    raw = swig.SymPRKIntegrator(0.001)
    with pytest.raises(mm.OpenMMException, match="temperature is -3 K"):
        raw.setThermostat(-3, 0.1, 1, 10, False)
    with pytest.raises(mm.OpenMMException, match="collision time is 0 ps"):
        raw.setThermostat(300, 0, 1, 10, False)
    with pytest.raises(mm.OpenMMException, match=r"interval \(thermostat_interval\) is 0 steps; expected .* from 1 to 2147483647"):
        raw.setThermostat(300, 0.1, 0, 10, False)
    # issue 27 #5: beyond a 32-bit int, the plugin's own message (not SWIG's OverflowError)
    with pytest.raises(mm.OpenMMException, match=r"thermostat_interval\) is 1000000000000 steps; expected .* to 2147483647"):
        raw.setThermostat(300, 0.1, 10**12, 10, False)
    largest = swig.SymPRKIntegrator(0.001)
    largest.setThermostat(300, 0.1, 2**31 - 1, 10, False)
    assert largest.getThermostatInterval() == 2**31 - 1
    with pytest.raises(mm.OpenMMException, match="0 degrees of freedom"):
        raw.setThermostat(300, 0.1, 1, 0, False)
    with pytest.raises(mm.OpenMMException, match="no thermostat"):
        raw.setThermostatTemperature(300)


def test_mts_thermostat_wraps_the_outer_step(water8):
    """With groups= the events come around the whole (outer) step: P and L stay, the bath exchanges energy."""
    from openmm_symprk.systems.forcegroups import split_forces

    system = mm.XmlSerializer.clone(water8.system)
    groups = split_forces(system, slow="nonbonded", substeps=2)
    ig = N(2 * unit.femtoseconds, "verlet", system=system, groups=groups, temperature=300, random_seed=2, thermostat_position="ends")
    assert "half events around the step (the outer step)" in ig.describe()
    ctx = mm.Context(system, ig, _platform("Reference"))
    ctx.setPositions(water8.positions)
    ctx.setVelocities(water8.velocities)
    m = water8.masses()
    x0, v0 = positions_velocities(ctx)
    ig.step(50)
    x1, v1 = positions_velocities(ctx)
    (p0, l0), (p1, l1) = _momenta(x0, v0, m), _momenta(x1, v1, m)
    assert np.linalg.norm(l1 - l0) <= 1e-11 * np.linalg.norm(l0)
    assert np.linalg.norm(p1 - p0) <= 1e-11 * float(np.sum(m[:, None] * np.abs(v0)))
    assert abs(ig.computeHeatBathEnergy().value_in_unit(unit.kilojoule_per_mole)) > 1e-3


# -- the two backends -------------------------------------------------------------------------------------------------
def test_native_and_custom_backends_sample_the_same_distribution():
    """Different random streams, the same ensemble: the mean peculiar kinetic energy of the free gas agrees
    between the backends (and with dof kT / 2) within 3 combined standard errors."""
    system, m, x, v = _ideal_gas(n=16, seed=21, massless=False)
    means = []
    for backend in ("native", "custom"):
        try:
            ig = SymplecticIntegrator(0.01, "verlet", system=system, temperature=250, collision_time=0.001,
                                      random_seed=21, backend=backend, thermostat_position="ends")
        except NotImplementedError as exc:
            pytest.skip(f"the custom backend's thermostat is not there yet: {exc}")
        ctx = mm.Context(system, ig, _platform("Reference"))
        ctx.setPositions(x)
        ctx.setVelocities(v)
        k = []
        for _ in range(1500):
            ig.step(1)
            xs, vs = positions_velocities(ctx)
            k.append(_peculiar_kinetic(xs, vs, m)[0])
        means.append(series_stats(k))
        del ctx
    target = 0.5 * (3 * 16 - 6) * R_KJ * 250
    (a, b) = means
    assert abs(a.mean - b.mean) <= 3 * math.hypot(a.se, b.se)
    for s in means:
        assert abs(s.mean - target) <= 3 * s.se


def test_native_seeded_run_repeats_whatever_the_reporting():
    """docs/thermostat.md: on the native backend a seeded NVT run repeats bit for bit on Reference even when one
    run also asks the Context for energies between steps (the thermostat's random stream is the plugin's own)."""
    from openmm_symprk.systems.scenes import water_cluster

    scene = water_cluster(4)

    def run(energies):
        ig = SymplecticIntegrator(2 * unit.femtoseconds, "verlet", system=scene.system, backend="native",
                                  temperature=300, random_seed=7, thermostat_position="ends")
        ctx = mm.Context(scene.system, ig, mm.Platform.getPlatformByName("Reference"))
        ctx.setPositions(scene.positions)
        ctx.setVelocities(scene.velocities)
        for _ in range(5):
            ig.step(10)
            if energies:
                ctx.getState(getEnergy=True)
        return ctx.getState(getPositions=True).getPositions(asNumpy=True)._value

    assert np.array_equal(run(False), run(True))
