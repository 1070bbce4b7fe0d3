"""The compiled CustomIntegrator programs on OpenMM: cost, conservation, orders, platforms, checkpoints, XML.

Tests that are about the program the compiler emits ask for backend="custom"; the native plugin is
checked against that program, bit for bit, in test_native.py."""
import warnings

import numpy as np
import openmm as mm
import openmm.app as app
import openmm.unit as unit
import pytest

from conftest import platform_available
from helpers import COMMON, counted, drift_after, evaluations, measure_order, reference_context
from openmm_symprk import SymplecticIntegrator, catalogue, resolve

SYMPLECTIC_SPLITTINGS = [m.name for m in catalogue.splittings()]




@pytest.mark.parametrize("name", ["verlet", "position-verlet", "omelyan-2", "yoshida-4", "mclachlan-atela-4",
                                  "blanes-moan-srkn6b-4", "kahan-li-6", "kahan-li-8"])
@pytest.mark.parametrize("scene_name", ["water8", "morse"])
def test_force_evaluations_per_step(name, scene_name, request):
    scene = request.getfixturevalue(scene_name)
    system, counter = counted(scene)
    ig = SymplecticIntegrator(1 * unit.femtoseconds, name, system=system, backend="custom")
    ctx = reference_context(system, ig, scene)  # noqa: F841 (kept alive while stepping)
    ig.step(1)
    assert evaluations(ig, [counter], 50) == (50 * catalogue[name].force_evals,)
    assert ig.program_info.force_evals == catalogue[name].force_evals


def test_force_evaluations_general_tableaux(morse):
    system, counter = counted(morse)
    for name, per_step in (("rk4", 4),):
        ig = SymplecticIntegrator(1 * unit.femtoseconds, name, system=system, allow_nonsymplectic=True)
        ctx = mm.Context(system, ig, mm.Platform.getPlatformByName("Reference"))
        ctx.setPositions(morse.positions)
        counter.n = 0
        ig.step(20)
        assert counter.n == 20 * per_step
        del ctx
    ig = SymplecticIntegrator(1 * unit.femtoseconds, "gauss-2", system=system)
    ctx = mm.Context(system, ig, mm.Platform.getPlatformByName("Reference"))
    ctx.setPositions(morse.positions)
    ctx.setVelocities(morse.velocities)
    counter.n = 0
    ig.step(1)
    iterations = ig.getGlobalVariableByName("symprk_iterations")
    assert 2 <= iterations < 20 and counter.n == 2 * iterations


@pytest.mark.parametrize("tolerance", [1e-3, 1e-10])
@pytest.mark.parametrize("name", SYMPLECTIC_SPLITTINGS)
def test_rigid_water_conserves_momentum_to_roundoff(name, tolerance, water8):
    ig = SymplecticIntegrator(2 * unit.femtoseconds, name, system=water8.system)
    ig.setConstraintTolerance(tolerance)
    ctx = water8.context(ig)
    dp, dl = drift_after(ctx, ig, water8.masses(), 1000)
    assert dl <= 1e-10 and dp <= 1e-10, f"{name}: dL/L={dl:.2e} dP={dp:.2e}"


@pytest.mark.parametrize("name", ["verlet", "position-verlet", "yoshida-4", "pefrl", "kahan-li-6"])
def test_ccma_constraints_conserve_momentum_at_any_tolerance(name, constrained):
    """Theorem 4.1: conservation does not depend on how well the multipliers are solved."""
    results = []
    for tol in (1e-3, 1e-10):
        ig = SymplecticIntegrator(1 * unit.femtoseconds, name, system=constrained.system)
        ig.setConstraintTolerance(tol)
        ctx = constrained.context(ig)
        results.append(drift_after(ctx, ig, constrained.masses(), 2000))
    for dp, dl in results:
        assert dl <= 1e-10 and dp <= 1e-10, f"{name}: {results}"


@pytest.mark.parametrize("name", ["gauss-2", "lobatto-iiia-iiib-3", "verlet", "yoshida-6"])
def test_unconstrained_symplectic_methods_conserve_L(name, morse):
    ig = SymplecticIntegrator(1 * unit.femtoseconds, name, system=morse.system)
    ctx = morse.context(ig)
    dp, dl = drift_after(ctx, ig, morse.masses(), 1000)
    assert dl <= 1e-10 and dp <= 1e-10


def test_rk4_loses_angular_momentum(morse):
    """The failure the theorem predicts: a non-symplectic method drifts by orders of magnitude more."""
    dls = {}
    for name in ("rk4", "yoshida-4"):  # same order, same stage count
        ig = SymplecticIntegrator(1 * unit.femtoseconds, name, system=morse.system, allow_nonsymplectic=True)
        ctx = morse.context(ig)
        dls[name] = drift_after(ctx, ig, morse.masses(), 1000)[1]
    assert dls["rk4"] > 1e-7 and dls["rk4"] > 1e4 * dls["yoshida-4"], dls


ORDER_CASES = ["verlet", "position-verlet", "yoshida-4", "mclachlan-atela-4", "mclachlan-atela-5", "kahan-li-6",
               "gauss-2", "lobatto-iiia-iiib-3", "rk4", "bcss-2", "bcss-3", "predescu-3"]


@pytest.mark.parametrize("name", ORDER_CASES)
def test_measured_order_on_openmm(name, morse):
    m = catalogue[name]
    orders, diffs = measure_order(
        morse, lambda h: SymplecticIntegrator(h, name, system=morse.system, allow_nonsymplectic=True),
        T_ps=0.02, steps=(10, 20, 40, 80))
    assert diffs[-1] > 1e-9
    assert abs(orders[-1] - m.order) < 0.35, f"{name}: {orders}"


CONSTRAINED_CASES = ["verlet", "position-verlet", "yoshida-4", "forest-ruth-4-position", "suzuki-4",
                     "yoshida-6", "kahan-li-6", "pefrl", "blanes-moan-srkn6b-4", "omelyan-2", "bcss-2", "bcss-3",
                     "predescu-3"]


@pytest.mark.parametrize("name", CONSTRAINED_CASES)
def test_measured_order_under_constraints(name, constrained):
    """RATTLE compositions keep their order; other splittings reach the recorded constrained_order."""
    m = catalogue[name]

    def make(h):
        ig = SymplecticIntegrator(h, name, system=constrained.system)
        ig.setConstraintTolerance(1e-14)
        return ig

    orders, diffs = measure_order(constrained, make, T_ps=0.04, steps=(10, 20, 40))
    assert diffs[-1] > 1e-10
    assert abs(orders[-1] - m.constrained_order) < 0.35, f"{name}: {orders}"


@pytest.mark.parametrize("platform,props", [
    ("CPU", {}),
    (COMMON, {"Precision": "double"}),
    (COMMON, {"Precision": "mixed"}),
])
def test_same_program_runs_on_other_platforms(platform, props, water8):
    if not platform_available(platform):
        pytest.skip(f"{platform} platform not available")
    results = {}
    for plat, pr in (("Reference", {}), (platform, props)):
        ig = SymplecticIntegrator(2 * unit.femtoseconds, "yoshida-4", system=water8.system, backend="custom")
        ctx = water8.context(ig, plat, pr)
        dp, dl = drift_after(ctx, ig, water8.masses(), 200)
        x = ctx.getState(getPositions=True).getPositions(asNumpy=True).value_in_unit(unit.nanometer)
        results[plat] = (x, dl)
        del ctx
    # same trajectory up to the platform's force precision over 0.4 ps
    assert np.max(np.abs(results["Reference"][0] - results[platform][0])) < 1e-3
    assert results[platform][1] < 1e-5  # single-precision force sums; exact_momentum fixes that


def test_checkpoint_round_trip_is_bitwise(constrained):
    ig = SymplecticIntegrator(1 * unit.femtoseconds, "yoshida-4", system=constrained.system)
    ctx = constrained.context(ig)
    ig.step(10)
    checkpoint = ctx.createCheckpoint()
    ig.step(25)
    first = ctx.getState(getPositions=True, getVelocities=True)
    ctx.loadCheckpoint(checkpoint)
    ig.step(25)
    second = ctx.getState(getPositions=True, getVelocities=True)
    for get in ("getPositions", "getVelocities"):
        a = getattr(first, get)(asNumpy=True)._value
        b = getattr(second, get)(asNumpy=True)._value
        assert np.array_equal(a, b)
    assert ig.steps_taken == 35


def test_xml_round_trip_gives_same_program(morse):
    ig = SymplecticIntegrator(1 * unit.femtoseconds, "gauss-2", system=morse.system)
    xml = mm.XmlSerializer.serialize(ig)
    copy = mm.XmlSerializer.deserialize(xml)
    assert type(copy) is mm.CustomIntegrator
    assert copy.getNumComputations() == ig.getNumComputations()
    for i in range(ig.getNumComputations()):
        assert copy.getComputationStep(i) == ig.getComputationStep(i)
    assert mm.XmlSerializer.serialize(copy) == xml
    # and it integrates identically
    finals = []
    for integ in (ig, copy):
        ctx = morse.context(integ)
        integ.step(20)
        finals.append(ctx.getState(getPositions=True).getPositions(asNumpy=True)._value)
        del ctx
    assert np.array_equal(finals[0], finals[1])


def test_works_in_simulation_with_reporters(water8, tmp_path):
    ig = SymplecticIntegrator(2 * unit.femtoseconds, "omelyan-2", system=water8.system)
    sim = app.Simulation(water8.topology, water8.system, ig, mm.Platform.getPlatformByName("Reference"))
    sim.context.setPositions(water8.positions)
    sim.context.setVelocities(water8.velocities)
    out = tmp_path / "log.csv"
    sim.reporters.append(app.StateDataReporter(str(out), 10, step=True, totalEnergy=True))
    sim.step(50)
    lines = out.read_text().strip().splitlines()
    energies = [float(l.split(",")[1]) for l in lines[1:]]
    assert len(energies) == 5 and np.ptp(energies) < 0.5
    sim.saveCheckpoint(str(tmp_path / "chk"))
    sim.loadCheckpoint(str(tmp_path / "chk"))
    assert sim.currentStep == 50


def _step_types(ig):
    """The computation types of the program after its header (the one-time probe block of the Context)."""
    types = [ig.getComputationStep(i)[0] for i in range(ig.getNumComputations())]
    return types[types.index(mm.CustomIntegrator.BlockEnd) + 1:]


def test_no_constraint_steps_without_constraints(morse, water8):
    free = SymplecticIntegrator(1 * unit.femtoseconds, "yoshida-4", system=morse.system, backend="custom")
    rattle = SymplecticIntegrator(1 * unit.femtoseconds, "yoshida-4", system=water8.system, backend="custom")
    cp, cv = mm.CustomIntegrator.ConstrainPositions, mm.CustomIntegrator.ConstrainVelocities
    assert cp not in _step_types(free) and cv not in _step_types(free)
    # one position projection per drift; one velocity projection per step, plus one before every drift that
    # would amplify the previous drift's constraint residual (yoshida-4: before its middle drift, -1.70 after 1.35)
    resolved = resolve("yoshida-4", constraints=True)
    assert _step_types(rattle).count(cp) == resolved.splitting.count("drift")
    assert sum(s.project_before for s in resolved.substeps) == 1
    assert _step_types(rattle).count(cv) == 1 + 1


def test_implicit_non_convergence_is_reported(morse):
    from openmm_symprk.integrators import ConvergenceWarning

    ig = SymplecticIntegrator(2 * unit.femtoseconds, "gauss-2", system=morse.system, max_iterations=2)
    ctx = morse.context(ig)
    with pytest.warns(ConvergenceWarning, match=r"gauss-2: the implicit stage iteration reached its cap on 5 step"):
        ig.step(5)
    ig2 = SymplecticIntegrator(2 * unit.femtoseconds, "gauss-2", system=morse.system)
    ctx2 = morse.context(ig2)
    import warnings

    with warnings.catch_warnings():
        warnings.simplefilter("error", ConvergenceWarning)
        ig2.step(5)


def test_virtual_sites_are_refused_by_the_custom_backend_wherever_it_is_chosen(water8, monkeypatch):
    """OpenMM 8.6's CustomIntegrator places virtual sites only at the end of a step on Reference and CPU, so forces
    inside the step see them one drift behind and the system heats (tests/integrators/test_reliability.py measures
    it on a TIP4P-Ew box).  Before, the custom backend ran such a System with a warning; now it refuses it by name
    wherever it is chosen: backend="custom", PRKIntegrator, a general tableau, and backend="auto"'s fallback."""
    from openmm_symprk import PRKIntegrator, plugin
    from openmm_symprk.integrators import VirtualSitesError

    mod = app.Modeller(water8.topology, water8.positions * unit.nanometer)
    ff = app.ForceField("tip4pew.xml")
    mod.addExtraParticles(ff)
    rigid = ff.createSystem(mod.topology, nonbondedMethod=app.NoCutoff, rigidWater=True, removeCMMotion=False)
    flexible = ff.createSystem(mod.topology, nonbondedMethod=app.NoCutoff, rigidWater=False, removeCMMotion=False)
    named = r"System has 8 virtual site\(s\) \(e.g. particle 3\).*one drift behind"
    with pytest.raises(VirtualSitesError, match=named + r".*backend='native'"):
        SymplecticIntegrator(1 * unit.femtoseconds, "verlet", system=rigid, backend="custom")
    with pytest.raises(VirtualSitesError, match=r"PRKIntegrator: the " + named):
        PRKIntegrator(0.001, "yoshida-4", system=rigid)
    with pytest.raises(VirtualSitesError, match="general PRK tableaux.*cannot run such a System"):
        SymplecticIntegrator(0.001, "gauss-2", system=flexible)  # only the custom backend runs it: refused
    monkeypatch.setattr(plugin, "available", lambda: False)
    monkeypatch.setattr(plugin, "unavailable_reason", lambda: "the plugin was not built (a test)")
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        with pytest.raises(VirtualSitesError, match=r"native backend.*is unavailable here \(the plugin was not "
                                                    r"built \(a test\)\); to fix it"):
            SymplecticIntegrator(0.001, "verlet", system=rigid)  # "auto" falls back to the custom backend
