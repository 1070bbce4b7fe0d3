"""The velocity-rescaling thermostat (temperature=): canonical sampling, what it keeps, its settings and errors.

Fixed seeds throughout; every statistical bound is stated where it is asserted (3 standard errors, the error of
correlated series from the statistical inefficiency of openmm_symprk.stats).  Tests of the shared API run on both
backends; the native ones are skipped while NativeSymplecticIntegrator does not take temperature= yet."""
import copy
import io
import pickle

import numpy as np
import openmm as mm
import openmm.app as app
import openmm.unit as unit
import pytest

from helpers import BACKENDS, BACKENDS_LONG, context
from openmm_symprk import SymplecticIntegrator, plugin
from openmm_symprk.integrators import deserialize
from openmm_symprk.integrators import thermostat_program as tp
from openmm_symprk.integrators.thermostat import thermostat_settings
from openmm_symprk.physics.temperature import R_KJ
from openmm_symprk.physics.velocity_rescaling import kept_velocities, rescaling_factor
from openmm_symprk.stats import block_stats, drift, series_stats
from openmm_symprk.stats.timeseries import statistical_inefficiency
from openmm_symprk.systems.prepare import equilibrate, maxwell_boltzmann, minimise
from openmm_symprk.systems.properties import masses, thermostat_degrees_of_freedom
from openmm_symprk.systems.scenes import water_box, water_cluster

REF = "Reference"
#: the periodic box and the barostat get their one-time ConservationWarning, as in NVE: not the subject here
pytestmark = pytest.mark.filterwarnings("ignore::openmm_symprk.systems.checks.ConservationWarning")
#: the CPU platform with forces summed in a fixed order.  CPU runs still do not repeat bit for bit from one process
#: to the next (PME included), and the dynamics is chaotic: the statistical tests, and the fixtures they start from,
#: run on Reference, so that their fixed seeds fix their outcome.
CPU_PROPERTIES = {"Threads": "2", "DeterministicForces": "true"}


# -- systems ---------------------------------------------------------------------------------------------
def ideal_gas(n=20, seed=0):
    """n particles of mixed masses and no forces, in vacuum (isolated): the peculiar kinetic energy of the
    canonical ensemble is exactly Gamma(N_f/2, kT)."""
    rng = np.random.default_rng(seed)
    system = mm.System()
    for k in range(n):
        system.addParticle(4.0 + 8.0 * (k % 3))
    x = rng.uniform(0.0, 2.0, size=(n, 3))
    return system, x, maxwell_boltzmann(system, x, 300.0, seed)


@pytest.fixture(scope="module")
def box():
    """64 rigid SPC/E waters, PME, periodic, minimised (system, positions)."""
    system, _, x = water_box("spce", n_waters=64, cutoff_nm=0.55)  # box ~1.24 nm at 0.997 g/cm3: room for the barostat
    return system, minimise(system, x, tolerance=10.0)


def momentum_conserving(system):
    """A copy of ``system`` with cutoff (reaction-field) electrostatics instead of PME: pairwise forces, whose net
    force is zero to round-off (PME's reciprocal-space forces have a small net force of their own)."""
    system = copy.deepcopy(system)
    for f in system.getForces():
        if isinstance(f, mm.NonbondedForce):
            f.setNonbondedMethod(mm.NonbondedForce.CutoffPeriodic)
    return system


@pytest.fixture(scope="module")
def cluster():
    return water_cluster(8)


# -- backends ----------------------------------------------------------------------------------------------
def state_arrays(ctx):
    st = ctx.getState(getPositions=True, getVelocities=True, getEnergy=True, enforcePeriodicBox=False)
    return (np.asarray(st.getPositions(asNumpy=True).value_in_unit(unit.nanometer)),
            np.asarray(st.getVelocities(asNumpy=True).value_in_unit(unit.nanometer / unit.picosecond)), st)


def peculiar_kinetic(x, v, m, keep_rotation):
    u = kept_velocities(x, v, m, keep_rotation)
    return 0.5 * float(np.sum(m[:, None] * (v - u) ** 2))


# -- degrees of freedom ----------------------------------------------------------------------------------------
def test_degrees_of_freedom_exclude_kept_motion_constraints_and_massless(cluster, box):
    n = cluster.system.getNumParticles()
    assert thermostat_degrees_of_freedom(cluster.system, True) == 3 * n - n - 6  # 3 SETTLE constraints per water
    assert thermostat_settings(cluster.system, temperature=300).dof == 3 * n - n - 6  # isolated: rotation kept too
    assert thermostat_settings(cluster.system, temperature=300).keep_rotation
    system, _ = box
    s = thermostat_settings(system, temperature=300)
    assert (s.dof, s.keep_rotation) == (3 * 192 - 192 - 3, False)  # periodic: only the centre of mass kept
    # a virtual site and a frozen (massless) particle count for nothing; a frozen particle makes it not isolated
    sys2 = mm.System()
    for m in (12.0, 1.0, 1.0, 0.0, 0.0):
        sys2.addParticle(m)
    sys2.setVirtualSite(3, mm.TwoParticleAverageSite(0, 1, 0.5, 0.5))
    sys2.addConstraint(0, 1, 0.1)
    sys2.addConstraint(1, 4, 0.1)  # to a frozen particle: still removes one degree of freedom
    assert thermostat_degrees_of_freedom(sys2, False) == 9 - 2 - 3
    assert thermostat_settings(sys2, temperature=300).dof == 4 and not thermostat_settings(sys2, temperature=300).keep_rotation


# -- bad input -------------------------------------------------------------------------------------------------
BAD = [
    (dict(temperature=True), TypeError, "temperature True is a truth value"),
    (dict(temperature=0), ValueError, "temperature must be positive and finite, got 0"),
    (dict(temperature=-300 * unit.kelvin), ValueError, "got -300 K"),
    (dict(temperature=float("nan")), ValueError, "got nan"),
    (dict(temperature=float("inf")), ValueError, "got inf"),
    (dict(temperature=300 * unit.nanometer), TypeError, "temperature 300 nm is not a temperature"),
    (dict(temperature="hot"), TypeError, "temperature 'hot' is not a temperature"),
    (dict(temperature=300, collision_time=0), ValueError, "collision_time must be positive and finite, got 0"),
    (dict(temperature=300, collision_time=-1 * unit.picoseconds), ValueError, "got -1 ps"),
    (dict(temperature=300, collision_time=float("inf")), ValueError, "got inf"),
    (dict(temperature=300, collision_time=5 * unit.kelvin), TypeError, "collision_time 5 K is not a time"),
    (dict(temperature=300, thermostat_interval=0), ValueError, "thermostat_interval must be >= 1, got 0"),
    (dict(temperature=300, thermostat_interval=True), TypeError, "thermostat_interval True is a truth value"),
    (dict(temperature=300, thermostat_interval=2.5), TypeError, "thermostat_interval must be a whole number, got 2.5"),
    (dict(temperature=300, random_seed=-1), ValueError, "random_seed must be >= 0, got -1"),
    (dict(temperature=300, random_seed=2**31), ValueError, "random_seed must be at most 2147483647"),
    (dict(collision_time=0.1), ValueError, "collision_time was given without temperature"),
    (dict(thermostat_interval=2, random_seed=3), ValueError,
     "thermostat_interval, random_seed were given without temperature"),
]


@pytest.mark.parametrize("backend", BACKENDS)
@pytest.mark.parametrize("options, error, message", BAD, ids=[str(i) for i in range(len(BAD))])
def test_bad_input_is_a_clear_error(backend, cluster, options, error, message):
    with pytest.raises(error, match=message.replace("(", r"\(").replace(")", r"\)")):
        SymplecticIntegrator(0.001, "verlet", system=cluster.system, backend=backend, **options)


@pytest.mark.parametrize("backend", BACKENDS)
def test_errors_about_the_system(backend):
    with pytest.raises(ValueError, match="temperature= needs system="):
        SymplecticIntegrator(0.001, "verlet", backend=backend, temperature=300)
    one = mm.System()
    one.addParticle(1.0)  # isolated: 3 - 3 = 0 (a diatomic has 6 - 3 - 2 = 1: tests/integrators/test_thermostat_edges)
    with pytest.raises(ValueError, match="no degrees of freedom to thermostat.*leaves 0 degrees of freedom"):
        SymplecticIntegrator(0.001, "verlet", system=one, backend=backend, temperature=300)


@pytest.mark.parametrize("backend", BACKENDS)
def test_accessors_and_their_errors(backend, cluster):
    ig = SymplecticIntegrator(0.002, "verlet", system=cluster.system, backend=backend, temperature=310,
                              collision_time=50 * unit.femtoseconds, thermostat_interval=4, random_seed=7, thermostat_position="ends")
    assert ig.getTemperature() == 310 * unit.kelvin
    assert ig.getCollisionTime().value_in_unit(unit.picoseconds) == pytest.approx(0.05, rel=1e-15)
    assert ig.getThermostatInterval() == 4 and ig.getRandomNumberSeed() == 7
    assert ig.thermostat_dof == ig.getThermostatDegreesOfFreedom() == 3 * 24 - 24 - 6
    ig.setTemperature(500 * unit.kelvin)
    ig.setCollisionTime(0.2)
    assert ig.getTemperature() == 500 * unit.kelvin and ig.getCollisionTime() == 0.2 * unit.picoseconds
    assert "stochastic velocity rescaling at 500 K" in ig.describe()
    with pytest.raises(ValueError, match="temperature must be positive and finite, got -1"):
        ig.setTemperature(-1)
    with pytest.raises(ValueError, match="random_seed must be >= 0, got -5"):
        ig.setRandomNumberSeed(-5)
    assert ig.getTemperature() == 500 * unit.kelvin  # a refused value changes nothing
    nve = SymplecticIntegrator(0.002, "verlet", system=cluster.system, backend=backend)
    assert nve.thermostat is None and nve.thermostat_dof is None and "thermostat" not in nve.describe()
    assert nve.computeHeatBathEnergy() == 0 * unit.kilojoule_per_mole
    for call in (nve.getTemperature, lambda: nve.setTemperature(300), nve.getThermostatDegreesOfFreedom):
        with pytest.raises(ValueError, match="created without temperature=, so it runs NVE"):
            call()


# -- the event is physics.velocity_rescaling's, bit for bit (CustomIntegrator program) ---------------------------
def test_custom_event_computes_rescaling_factor_exactly(cluster):
    ig = SymplecticIntegrator(0.002, "verlet", system=cluster.system, backend="custom", temperature=300,
                              random_seed=3, thermostat_position="ends")
    ctx = context(cluster.system, ig, cluster.positions, cluster.velocities)
    m = masses(cluster.system)
    settings = ig.thermostat
    assert np.sum(ig.getPerDofVariableByName(tp.MASK_VAR)) == 0  # filled at the first step
    for _ in range(5):
        ig.step(1)
        g = ig.getGlobalVariableByName
        kpec = g(tp.KINETIC_VAR)
        alpha, new = rescaling_factor(kpec, settings.target_kinetic, settings.dof, g(tp.PREFIX + "c"),
                                      g(tp.PREFIX + "r1"), g(tp.PREFIX + "chi2"))
        assert (alpha, new) == (g(tp.ALPHA_VAR), g(tp.NEW_KINETIC_VAR))
        assert g(tp.PREFIX + "c") == settings.c_half(0.002)
        x, v, _ = state_arrays(ctx)
        assert peculiar_kinetic(x, v, m, True) == pytest.approx(new, rel=1e-12)
    mask = np.array(ig.getPerDofVariableByName(tp.MASK_VAR))
    assert mask.sum() == settings.dof - 1 and set(np.unique(mask)) == {0.0, 1.0}
    # a Context reinitialized without its state loses per-DOF values set while bound: the integrator notices (the
    # mask is missing: a new run) and fills the mask again before stepping
    ctx.reinitialize(preserveState=False)
    ctx.setPositions(cluster.positions)
    ctx.setVelocities(cluster.velocities)
    assert np.sum(ig.getPerDofVariableByName(tp.MASK_VAR)) == 0
    heat = ig.computeHeatBathEnergy()
    ig.step(1)
    assert ig.computeHeatBathEnergy() != heat
    assert np.sum(ig.getPerDofVariableByName(tp.MASK_VAR)) == settings.dof - 1
    # and the program guards itself: steps run on a mask without its dof - 1 ones (OpenMM's own step, past the
    # integrator's checks) change nothing through the events and raise the flag
    heat = ig.computeHeatBathEnergy()
    ig.setPerDofVariableByName(tp.MASK_VAR, [mm.Vec3(0, 0, 0)] * cluster.system.getNumParticles())
    mm.CustomIntegrator.step(ig, 2)
    assert ig.getGlobalVariableByName(tp.LOST_MASK_VAR) == 1.0 and ig.getGlobalVariableByName(tp.HEAT_BATH_VAR) == \
        heat.value_in_unit(unit.kilojoule_per_mole)


# -- thermostat off: the NVE program, bit for bit ------------------------------------------------------------------
def _computations(ig):
    return [ig.getComputationStep(i) for i in range(ig.getNumComputations())]


def _strip_thermostat(nvt):
    """A plain CustomIntegrator holding ``nvt``'s program without the thermostat's computations and variables."""
    out = mm.CustomIntegrator(nvt.getStepSize())
    for i in range(nvt.getNumGlobalVariables()):
        name = nvt.getGlobalVariableName(i)
        if not name.startswith((tp.PREFIX, "symprk_meta_")):
            out.addGlobalVariable(name, nvt.getGlobalVariable(i))
    for i in range(nvt.getNumPerDofVariables()):
        name = nvt.getPerDofVariableName(i)
        if not name.startswith(tp.PREFIX):
            out.addPerDofVariable(name, 0.0)
            values = nvt.getPerDofVariable(i)
            if values:
                out.setPerDofVariable(out.getNumPerDofVariables() - 1, values)
    for kind, var, expr in _computations(nvt):
        if tp.PREFIX in var or tp.PREFIX in expr:
            continue
        {0: out.addComputeGlobal, 1: out.addComputePerDof, 2: out.addComputeSum}.get(
            kind, lambda v, e, k=kind: _add_other(out, k, v, e))(var, expr)
    return out


def _add_other(ig, kind, var, expr):
    C = mm.CustomIntegrator
    if kind == C.ConstrainPositions:
        ig.addConstrainPositions()
    elif kind == C.ConstrainVelocities:
        ig.addConstrainVelocities()
    elif kind == C.UpdateContextState:
        ig.addUpdateContextState()
    elif kind == C.IfBlockStart:
        ig.beginIfBlock(expr)
    elif kind == C.BlockEnd:
        ig.endBlock()
    else:
        raise AssertionError(f"unexpected computation kind {kind}")


@pytest.mark.parametrize("method, options", [("verlet", {}), ("omelyan-2", {"exact_momentum": True}),
                                             ("yoshida-4", {"groups": [(0, 2)]})])
def test_thermostat_off_is_the_nve_program_bit_for_bit(cluster, method, options):
    nve = SymplecticIntegrator(0.002, method, system=cluster.system, backend="custom", **options)
    # the ends placement adds its events around the unchanged NVE step (the middle one splits the central drift)
    nvt = SymplecticIntegrator(0.002, method, system=cluster.system, backend="custom", temperature=300,
                               thermostat_position="ends", **options)
    xml = mm.XmlSerializer.serialize(nve)
    assert tp.PREFIX not in xml and "gaussian" not in xml and nve.thermostat is None
    # the thermostat only adds its own computations (two half events) and variables to the NVE program
    stripped = _strip_thermostat(nvt)
    assert _computations(stripped) == _computations(nve)
    assert sum("gaussian" in e for _, _, e in _computations(nvt)) == 4  # r1 and chi2, twice per step
    # ... so without them the trajectory is the NVE one, bit for bit
    stripped.setGlobalVariableByName("symprk_signature", nve.getGlobalVariableByName("symprk_signature"))
    runs = []
    for ig in (nve, stripped):
        ctx = context(cluster.system, ig, cluster.positions, cluster.velocities)
        ig.step(20)
        x, v, _ = state_arrays(ctx)
        runs.append((x.tobytes(), v.tobytes()))
        del ctx
    assert runs[0] == runs[1]


# -- canonical sampling --------------------------------------------------------------------------------------------
def _peculiar_kinetic_every(ig, ctx, m, every: int, samples: int) -> np.ndarray:
    """The peculiar kinetic energy (rigid rotation kept) after each of ``samples`` blocks of ``every`` steps."""
    out = []
    for _ in range(samples):
        ig.step(every)
        xs, vs, _ = state_arrays(ctx)
        out.append(peculiar_kinetic(xs, vs, m, True))
    return np.array(out)


@pytest.mark.parametrize("backend", BACKENDS)
def test_ideal_gas_kinetic_energy_is_gamma_distributed(backend):
    """No forces, isolated: the peculiar kinetic energy of the canonical ensemble is Gamma(N_f/2, kT) with
    N_f = 3 N - 6.  KS test at the 1% level on subsampled (statistical inefficiency) values, and mean and
    variance within 3 standard errors; N_f +- 3 would move the mean by 5.6%, ~13 standard errors."""
    from scipy import stats

    system, x, v = ideal_gas(20, seed=4)
    T = 300.0
    ig = SymplecticIntegrator(0.002, "verlet", system=system, backend=backend, temperature=T,
                              collision_time=0.004, thermostat_interval=5, random_seed=11, thermostat_position="ends")
    dof = ig.thermostat_dof
    assert dof == 3 * 20 - 6
    ctx = context(system, ig, x, v)
    m = masses(system)
    ig.step(50)
    K = _peculiar_kinetic_every(ig, ctx, m, 5, 2000)
    kT = R_KJ * T
    g = statistical_inefficiency(K)
    assert g < 2.0  # c^2 = exp(-2.5) per 5 steps: nearly independent
    sub = K[::int(np.ceil(g))]
    assert stats.kstest(sub, stats.gamma(dof / 2, scale=kT).cdf).pvalue > 0.01
    mean = series_stats(K)
    assert abs(mean.mean - dof * kT / 2) < 3 * mean.se
    var = series_stats((K - K.mean()) ** 2)
    assert abs(var.mean - dof * kT ** 2 / 2) < 3 * var.se
    # a new target acts on the running Context
    ig.setTemperature(2 * T)
    ig.step(200)
    s2 = series_stats(_peculiar_kinetic_every(ig, ctx, m, 5, 300))
    assert abs(s2.mean - dof * kT) < 3 * s2.se


class Recorder:
    """A Simulation reporter keeping the positions and velocities of every report (float64)."""

    def __init__(self, interval):
        self.interval, self.x, self.v, self.volume = interval, [], [], []

    def describeNextReport(self, simulation):
        return {"steps": self.interval - simulation.currentStep % self.interval, "periodic": False,
                "include": ["positions", "velocities"]}

    def report(self, simulation, state):
        self.x.append(np.asarray(state.getPositions(asNumpy=True).value_in_unit(unit.nanometer)))
        self.v.append(np.asarray(state.getVelocities(asNumpy=True).value_in_unit(unit.nanometer / unit.picosecond)))
        self.volume.append(state.getPeriodicBoxVolume().value_in_unit(unit.nanometer ** 3))


@pytest.fixture(scope="module")
def equilibrated_box(box):
    """The PME box after 2 ps of OpenMM's LangevinMiddleIntegrator at 300 K: (system, positions)."""
    system, x = box
    x, _ = equilibrate(system, x, 300.0, 2.0, seed=23, platform=REF)
    return system, x


@pytest.fixture(scope="module")
def npt_box(box):
    """The PME box with a MonteCarloBarostat (1 bar, every 5 steps), equilibrated at 300 K and 1 bar by 4 ps of
    OpenMM's LangevinMiddleIntegrator: (system, positions, box vectors)."""
    system, x = box
    system = copy.deepcopy(system)
    barostat = mm.MonteCarloBarostat(1 * unit.bar, 300 * unit.kelvin, 5)
    barostat.setRandomNumberSeed(17)
    system.addForce(barostat)
    ig = mm.LangevinMiddleIntegrator(300 * unit.kelvin, 5 / unit.picosecond, 2 * unit.femtoseconds)
    ig.setRandomNumberSeed(17)
    ctx = mm.Context(system, ig, mm.Platform.getPlatformByName(REF))
    ctx.setPositions(x)
    ctx.setVelocitiesToTemperature(300 * unit.kelvin, 17)
    ig.step(2000)
    st = ctx.getState(getPositions=True)
    return system, np.asarray(st.getPositions(asNumpy=True).value_in_unit(unit.nanometer)), st.getPeriodicBoxVectors()


def _water_box_run(backend, system, x, steps, seed=5, platform="CPU", equilibration=500,
                   box_vectors=None, collision_time=0.1, step_ps=0.002, position="ends"):
    from openmm_symprk.conservation import ConservationReporter

    T = 300.0
    ig = SymplecticIntegrator(step_ps, "verlet", system=system, backend=backend, temperature=T,
                              collision_time=collision_time, random_seed=seed, thermostat_position=position)
    top = app.Topology()
    chain = top.addChain()
    for _ in range(system.getNumParticles() // 3):
        res = top.addResidue("HOH", chain)
        o = top.addAtom("O", app.element.oxygen, res)
        for name in ("H1", "H2"):
            top.addBond(o, top.addAtom(name, app.element.hydrogen, res))
    top.setPeriodicBoxVectors(system.getDefaultPeriodicBoxVectors())
    sim = app.Simulation(top, system, ig, mm.Platform.getPlatformByName(platform),
                         CPU_PROPERTIES if platform == "CPU" else {})
    if box_vectors is not None:
        sim.context.setPeriodicBoxVectors(*box_vectors)
    sim.context.setPositions(x)
    sim.context.setVelocities(maxwell_boltzmann(system, x, 250.0, seed))  # starts cold: the thermostat heats it
    sim.step(equilibration)
    rec, sdr_out = Recorder(10), io.StringIO()
    sim.reporters += [rec, app.StateDataReporter(sdr_out, 10, temperature=True, kineticEnergy=True),
                      ConservationReporter(io.StringIO(), 10, warn=False)]
    sim.step(steps)
    ig.final_heat_bath = ig.computeHeatBathEnergy()  # while the Context lives
    return ig, rec, sdr_out.getvalue(), sim.reporters[2], system


@pytest.mark.parametrize("backend", BACKENDS_LONG)
def test_water_box_temperature_and_kinetic_energy_are_canonical(backend, equilibrated_box):
    """64 rigid waters (PME), equilibrated, collision time 0.05 ps, 8 ps sampled every 20 fs: <T> of the peculiar
    kinetic energy within 3 standard errors of 300 K, the mean and variance of K within 3 standard errors of
    N_f kT/2 and N_f (kT)^2/2 (all from 8 blocks of 1 ps, about 7 times the slow tail of K's autocorrelation);
    StateDataReporter's and ConservationReporter's temperature columns agree with it."""
    system, x = equilibrated_box
    ig, rec, sdr, cons, _ = _water_box_run(backend, system, x, 4000, platform=REF, equilibration=250,
                                           collision_time=0.05)
    cons_text = cons._out.getvalue()
    m = masses(system)
    dof = ig.thermostat_dof
    kT = R_KJ * 300.0
    K = np.array([peculiar_kinetic(xs, vs, m, False) for xs, vs in zip(rec.x, rec.v)])
    T = block_stats(2 * K / (dof * R_KJ), 8)  # blocks: K's slow tail (openmm_symprk.stats.block_stats)
    assert abs(T.mean - 300.0) < 3 * T.se and T.se < 4.0  # resolves 300 K to ~1 %
    # the variance of K, also from the blocks (squared deviations are too heavy-tailed for the statistical
    # inefficiency)
    blocks = K.reshape(8, -1)
    means, variances = blocks.mean(axis=1), ((blocks - K.mean()) ** 2).mean(axis=1)
    assert abs(means.mean() - dof * kT / 2) < 3 * means.std(ddof=1) / np.sqrt(8)
    assert abs(variances.mean() - dof * kT ** 2 / 2) < 3 * variances.std(ddof=1) / np.sqrt(8)
    # StateDataReporter prints the integrator's computeSystemTemperature(): with the ends placement the thermostat's
    # temperature is that of the reported (on-step) peculiar velocities, with the thermostat's degrees of freedom
    rows = [line.split(",") for line in sdr.splitlines()[1:]]
    assert np.allclose([float(r[1]) for r in rows], 2 * K / (dof * R_KJ), rtol=1e-9, atol=0)
    # ConservationReporter reports the effective energy (total + heat bath) and says so in its header
    assert cons.records[-1]["heat_bath"] == ig.final_heat_bath.value_in_unit(unit.kilojoule_per_mole) != 0
    assert '"Total + heat-bath energy (kJ/mol)"' in cons_text
    # ConservationReporter's translational (3 N_mol - 3 degrees of freedom) and rotational (3 N_mol) temperatures
    # split the thermostatted kinetic energy exactly (rigid water: no internal motion).  (Whether they are equal is
    # the integrator's equipartition at this step, docs/equipartition.md, not the thermostat's.)
    n_mol = system.getNumParticles() // 3
    assert (3 * n_mol - 3) + 3 * n_mol == dof
    combined = np.array([((3 * n_mol - 3) * r["T_trans"] + 3 * n_mol * r["T_rot"]) / dof for r in cons.records])
    assert np.allclose(combined, 2 * K / (dof * R_KJ), rtol=1e-9, atol=0)


@pytest.mark.parametrize("backend", BACKENDS)
def test_state_data_reporter_prints_the_thermostats_temperature(backend, equilibrated_box):
    """OpenMM's StateDataReporter prints computeSystemTemperature() where the integrator has it.  The PME box at 4 fs
    with the thermostat in the middle: the printed column is the thermostat's temperature, 300 K within 3 standard
    errors (blocks of 1 ps), and the reporter's kinetic-energy column and the recorded velocities read the same
    temperature (paired, within 0.5 K): the State holds the thermostat point's velocities, changed only by the RATTLE
    correction of the half drift after the event (measured: 0.16 K low, 0.05 %).  Before, it held the on-step ones,
    half a kick later, which read more than 2 K low (a stiff mode of frequency w reads T (1 - h^2 w^2/4) there)."""
    system, x = equilibrated_box
    ig, rec, sdr, _, _ = _water_box_run(backend, system, x, 2000, platform=REF, equilibration=250, collision_time=0.05,
                                        step_ps=0.004, position="middle")
    assert ig.thermostat_position == "middle"
    m, dof = masses(system), ig.thermostat_dof
    recorded = np.array([2 * peculiar_kinetic(xs, vs, m, False) / (dof * R_KJ) for xs, vs in zip(rec.x, rec.v)])
    rows = [line.split(",") for line in sdr.splitlines()[1:]]
    printed = np.array([float(r[1]) for r in rows])
    kinetic = np.array([2 * float(r[0]) / (dof * R_KJ) for r in rows])  # the State's kinetic energy (P = 0)
    assert len(printed) == len(recorded) == 200
    t = block_stats(printed, 8)
    assert abs(t.mean - 300.0) < 3 * t.se and t.se < 4.0, t
    for other in (recorded, kinetic):
        d = block_stats(other - printed, 8)  # paired: the thermostat's noise cancels
        assert abs(d.mean) < 0.5 and d.se < 0.1, d


@pytest.mark.parametrize("backend", BACKENDS_LONG)
def test_npt_with_monte_carlo_barostat(backend, npt_box):
    """MonteCarloBarostat (1 bar, every 5 steps) with the thermostat (collision time 0.02 ps) on the PME box, from
    a state equilibrated at 300 K and 1 bar: the volume moves and <T> over 4 ps is within 3 standard errors (from
    10 blocks of 0.4 ps) of 300 K.  (The momentum with a barostat: test_periodic_box_keeps_momentum.)"""
    system, x, box_vectors = npt_box
    ig, rec, _, _, _ = _water_box_run(backend, system, x, 2000, seed=6, equilibration=200, box_vectors=box_vectors,
                                      platform=REF, collision_time=0.02)
    assert np.ptp(rec.volume) > 1e-3 * np.mean(rec.volume)
    m = masses(system)
    dof = ig.thermostat_dof
    T = block_stats([2 * peculiar_kinetic(xs, vs, m, False) / (dof * R_KJ) for xs, vs in zip(rec.x, rec.v)], 10)
    assert abs(T.mean - 300.0) < 3 * T.se and T.se < 4.0  # resolves 300 K to ~1 %


# -- what the thermostat keeps -------------------------------------------------------------------------------------
@pytest.mark.parametrize("backend", BACKENDS)
@pytest.mark.parametrize("barostat", [False, True], ids=["nvt", "npt"])
def test_periodic_box_keeps_momentum(backend, box, barostat):
    """64 waters in a periodic box with pairwise forces (net force zero to round-off), thermostat far from the
    state (400 K, tau 0.02 ps), with or without a MonteCarloBarostat (every 5 steps): the total momentum after
    300 steps is its initial value to round-off."""
    system, x = box
    system = momentum_conserving(system)
    if barostat:
        force = mm.MonteCarloBarostat(1 * unit.bar, 400 * unit.kelvin, 5)
        force.setRandomNumberSeed(3)
        system.addForce(force)
    ig = SymplecticIntegrator(0.002, "verlet", system=system, backend=backend, temperature=400,
                              collision_time=0.02, random_seed=31, thermostat_position="ends")
    v = maxwell_boltzmann(system, x, 300.0, 3) + np.array([0.3, -0.2, 0.1])  # a moving box: P is not zero
    ctx = context(system, ig, x, v)
    m = masses(system)
    P0 = (m[:, None] * state_arrays(ctx)[1]).sum(0)
    ig.step(300)
    _, v1, _ = state_arrays(ctx)
    assert np.linalg.norm((m[:, None] * v1).sum(0) - P0) < 1e-12 * float(np.sum(m[:, None] * np.abs(v1)))
    assert ig.computeHeatBathEnergy().value_in_unit(unit.kilojoule_per_mole) < -50  # it heated the box
    if barostat:
        assert ctx.getState().getPeriodicBoxVolume() != system.getDefaultPeriodicBoxVectors()[0][0] ** 3


@pytest.mark.parametrize("backend", BACKENDS)
@pytest.mark.parametrize("options", [{}, {"exact_momentum": True}])
def test_isolated_cluster_keeps_momentum_and_angular_momentum(backend, cluster, options):
    """8 spinning rigid waters in vacuum at 500 K target (far from their state, so the thermostat works hard):
    P and L (about the origin) to round-off after 300 steps, and the velocity constraints stay satisfied."""
    system = cluster.system
    ig = SymplecticIntegrator(0.002, "verlet", system=system, backend=backend, temperature=500,
                              collision_time=0.01, random_seed=2, **options, thermostat_position="ends")
    ctx = context(system, ig, cluster.positions, cluster.velocities)
    m = masses(system)
    x0, v0, _ = state_arrays(ctx)
    P0, L0 = (m[:, None] * v0).sum(0), (m[:, None] * np.cross(x0, v0)).sum(0)
    heat0 = ig.computeHeatBathEnergy()
    ig.step(300)
    x, v, _ = state_arrays(ctx)
    P, L = (m[:, None] * v).sum(0), (m[:, None] * np.cross(x, v)).sum(0)
    scale = float(np.sum(m[:, None] * np.abs(v)))
    assert np.linalg.norm(P - P0) < 1e-12 * scale
    assert np.linalg.norm(L - L0) < 1e-11 * np.linalg.norm(L0)
    assert ig.computeHeatBathEnergy() != heat0  # it did act
    # velocity constraints: relative velocity along every bond ~ 0 (SETTLE's tolerance), as in NVE
    i, j = np.array([system.getConstraintParameters(k)[:2] for k in range(system.getNumConstraints())]).T
    r, dv = x[i] - x[j], v[i] - v[j]
    assert np.max(np.abs(np.sum(r * dv, axis=1)) / (np.linalg.norm(r, axis=1) * np.linalg.norm(dv, axis=1))) < 1e-6


@pytest.mark.parametrize("backend", BACKENDS_LONG)
def test_effective_energy_drift_equals_the_nve_drift(backend):
    """27 rigid waters in vacuum, equilibrated at 300 K (2 ps of Langevin dynamics), omelyan-2 at 2 fs: eight
    independent 2-ps replicas (Maxwell-Boltzmann velocities of their own seed) of NVE and of NVT at 300 K.  (In
    equilibrium: while heat flows in or out, the effective energy also collects the integrator's error of the
    energy exchanged.)  The mean least-squares slope of total + heat-bath energy of
    the NVT replicas equals that of the total energy of the NVE replicas within 3 combined standard errors,
    each taken from the spread of its eight replicas (independent runs: no model of the correlations, which for
    the heat-bath energy are a random walk's)."""
    scene = water_cluster(27, temperature=300.0, angular_velocity=(0.0, 0.0, 0.0))
    system = scene.system
    x, _ = equilibrate(system, scene.positions, 300.0, 2.0, seed=7, platform=REF)
    slopes = {"nve": [], "nvt": []}
    for replica in range(8):
        v = maxwell_boltzmann(system, x, 300.0, 100 + replica)
        for kind, options in (("nve", {}), ("nvt", {"temperature": 300, "random_seed": 40 + replica})):
            ig = SymplecticIntegrator(0.002, "omelyan-2", system=system, backend=backend, **options)
            ctx = context(system, ig, x, v)
            t, e = [], []
            for _ in range(100):
                ig.step(10)
                st = ctx.getState(getEnergy=True)
                t.append(st.getTime().value_in_unit(unit.picosecond))
                e.append((st.getPotentialEnergy() + st.getKineticEnergy() + ig.computeHeatBathEnergy())
                         .value_in_unit(unit.kilojoule_per_mole))
            slopes[kind].append(drift(t, e).slope)
            del ctx
    nve, nvt = (np.array(slopes[k]) for k in ("nve", "nvt"))
    se = np.hypot(nve.std(ddof=1), nvt.std(ddof=1)) / np.sqrt(len(nve))
    assert abs(nvt.mean() - nve.mean()) < 3 * se, (nve, nvt)
    # and both are small: below 0.05 kT/ns per degree of freedom
    dof = 3 * system.getNumParticles() - system.getNumConstraints() - 6
    for s in (nve, nvt):
        assert abs(s.mean()) * 1000 / dof < 0.05 * R_KJ * 300


# -- every n steps, MTS -----------------------------------------------------------------------------------------
@pytest.mark.parametrize("backend", BACKENDS)
def test_every_n_steps_half_events_around_n_steps(backend, cluster):
    """thermostat_interval=3: a half event before steps 0, 3, 6, ... and after steps 2, 5, 8, ...: the heat-bath
    energy changes in exactly those steps (in between, the NVE steps do not touch it)."""
    ig = SymplecticIntegrator(0.002, "verlet", system=cluster.system, backend=backend, temperature=400,
                              thermostat_interval=3, random_seed=4, thermostat_position="ends")
    ctx = context(cluster.system, ig, cluster.positions, cluster.velocities)
    heat = [ig.computeHeatBathEnergy()._value]
    for _ in range(9):
        ig.step(1)
        heat.append(ig.computeHeatBathEnergy()._value)
    changed = [k for k in range(9) if heat[k + 1] != heat[k]]  # step k (0-based) ran an event
    assert changed == [0, 2, 3, 5, 6, 8]
    del ctx


@pytest.mark.parametrize("backend", BACKENDS)
def test_mts_thermostat_wraps_the_outer_step(backend, cluster):
    """groups=[(1, 1), (0, 3)]: still two half events per (outer) step, P and L kept."""
    system = copy.deepcopy(cluster.system)
    for f in system.getForces():
        if isinstance(f, mm.NonbondedForce):
            f.setForceGroup(1)
    ig = SymplecticIntegrator(0.004, "verlet", system=system, backend=backend, temperature=300,
                              groups=[(1, 1), (0, 3)], random_seed=8, thermostat_position="ends")
    if backend == "custom":
        assert sum("gaussian" in e for _, _, e in _computations(ig)) == 4
    ctx = context(system, ig, cluster.positions, cluster.velocities)
    m = masses(system)
    x0, v0, _ = state_arrays(ctx)
    ig.step(100)
    x, v, _ = state_arrays(ctx)
    assert np.linalg.norm((m[:, None] * (v - v0)).sum(0)) < 1e-12 * float(np.sum(m[:, None] * np.abs(v)))
    L0, L = (m[:, None] * np.cross(x0, v0)).sum(0), (m[:, None] * np.cross(x, v)).sum(0)
    assert np.linalg.norm(L - L0) < 1e-11 * np.linalg.norm(L0)


# -- checkpoints, XML, pickle, copies --------------------------------------------------------------------------------
@pytest.mark.parametrize("backend", BACKENDS)
def test_checkpoint_continues_bit_for_bit(backend, cluster):
    """A run continued from a checkpoint (heat-bath energy and random state in it) is the uninterrupted run, bit
    for bit (Reference), in the same Context and in a new one."""
    def make():
        return SymplecticIntegrator(0.002, "verlet", system=cluster.system, backend=backend, temperature=350,
                                    collision_time=0.02, random_seed=12, thermostat_position="ends")

    ig = make()
    ctx = context(cluster.system, ig, cluster.positions, cluster.velocities)
    ig.step(30)
    chk = ctx.createCheckpoint()
    heat_at_chk = ig.computeHeatBathEnergy()
    ig.step(30)
    x1, v1, _ = state_arrays(ctx)
    heat1 = ig.computeHeatBathEnergy()
    ctx.loadCheckpoint(chk)
    assert ig.computeHeatBathEnergy() == heat_at_chk
    ig.step(30)
    x2, v2, _ = state_arrays(ctx)
    assert (x2.tobytes(), v2.tobytes(), ig.computeHeatBathEnergy()) == (x1.tobytes(), v1.tobytes(), heat1)
    del ctx
    ig2 = make()
    ctx2 = context(cluster.system, ig2, cluster.positions, cluster.velocities)
    ctx2.loadCheckpoint(chk)
    ig2.step(30)
    x3, v3, _ = state_arrays(ctx2)
    assert (x3.tobytes(), v3.tobytes(), ig2.computeHeatBathEnergy()) == (x1.tobytes(), v1.tobytes(), heat1)


@pytest.mark.parametrize("backend", BACKENDS)
@pytest.mark.parametrize("how", ["xml", "pickle", "deepcopy"])
def test_copies_keep_the_thermostat(backend, cluster, how):
    ig = SymplecticIntegrator(0.002, "omelyan-2", system=cluster.system, backend=backend, temperature=320,
                              collision_time=0.3, thermostat_interval=2, random_seed=21, thermostat_position="ends")
    ig.setTemperature(330)  # changed after creation: the copy has the current value
    copied = {"xml": lambda: deserialize(mm.XmlSerializer.serialize(ig)),
              "pickle": lambda: pickle.loads(pickle.dumps(ig)),
              "deepcopy": lambda: copy.deepcopy(ig)}[how]()
    assert type(copied) is type(ig)
    assert copied.getTemperature() == 330 * unit.kelvin
    assert copied.getCollisionTime().value_in_unit(unit.picoseconds) == pytest.approx(0.3, rel=1e-15)
    assert (copied.getThermostatInterval(), copied.getRandomNumberSeed(), copied.thermostat_dof) == \
        (2, 21, ig.thermostat_dof)
    assert copied.thermostat.keep_rotation and "330 K" in copied.describe()
    # and it runs the same trajectory (same seed, fresh Contexts)
    runs = []
    for integrator in (ig, copied):
        ctx = context(cluster.system, integrator, cluster.positions, cluster.velocities)
        integrator.step(10)
        runs.append((state_arrays(ctx)[1].tobytes(), integrator.computeHeatBathEnergy()))
        del ctx
    assert runs[0] == runs[1]


@pytest.mark.parametrize("backend", BACKENDS)
def test_no_conservation_warning_for_its_own_thermostat(backend, cluster):
    """The package's thermostat keeps P (and L here), so neither the integrator nor ConservationReporter warns
    about it, as they do about OpenMM's thermostats."""
    import warnings

    from openmm_symprk.conservation import ConservationReporter
    from openmm_symprk.systems.checks import ConservationWarning

    with warnings.catch_warnings():
        warnings.simplefilter("error", ConservationWarning)
        ig = SymplecticIntegrator(0.002, "verlet", system=cluster.system, backend=backend, temperature=300,
                                  random_seed=1, thermostat_position="ends")
        sim = app.Simulation(cluster.topology, cluster.system, ig, mm.Platform.getPlatformByName(REF))
        sim.context.setPositions(cluster.positions)
        sim.context.setVelocities(cluster.velocities)
        reporter = ConservationReporter(io.StringIO(), 5)
        sim.reporters.append(reporter)
        sim.step(10)
    assert reporter.issues == [] and len(reporter.records) == 2


@pytest.mark.parametrize("method", ["gauss-2", "lobatto-iiia-iiib-3"])
def test_general_tableaux_take_the_thermostat_too(method):
    """The CustomIntegrator backend's implicit PRK methods with the thermostat (Morse molecule, isolated: N_f = 6):
    the events wrap the stages, P and L stay to round-off, heat is exchanged."""
    from openmm_symprk.systems.scenes import morse_molecule

    scene = morse_molecule()
    ig = SymplecticIntegrator(0.0005, method, system=scene.system, temperature=600, collision_time=0.01,
                              random_seed=6, thermostat_position="ends")
    assert ig.backend == "custom" and ig.thermostat_dof == 6
    assert sum("gaussian" in e for _, _, e in _computations(ig)) == 4
    ctx = context(scene.system, ig, scene.positions, scene.velocities)
    m = masses(scene.system)
    x0, v0, _ = state_arrays(ctx)
    ig.step(200)
    x, v, _ = state_arrays(ctx)
    scale = float(np.sum(m[:, None] * np.abs(v)))
    assert np.linalg.norm((m[:, None] * (v - v0)).sum(0)) < 1e-12 * scale
    L0, L = (m[:, None] * np.cross(x0, v0)).sum(0), (m[:, None] * np.cross(x, v)).sum(0)
    assert np.linalg.norm(L - L0) < 1e-11 * np.linalg.norm(L0)
    assert ig.computeHeatBathEnergy().value_in_unit(unit.kilojoule_per_mole) != 0
