"""The Common kernel's fusion (SymPRKIntegrator.setKernelFusion): fewer launches, the same trajectory.

On OpenCL the fused execution (FuseAll, the default, and FuseSegments: thermostat events as a reduction launch of
their own) is compared with the plain reading of the plan (FuseNone: one operation at a time, every step ending at
the step point), after each of two step() calls, the State read between them:

* without constraints the positions and velocities are the same bit for bit (each fused launch does its operations'
  arithmetic in their order), with the thermostat in both placements, multiple time stepping and several methods;
* with constraints (SETTLE, CCMA) they agree to far below the constraint tolerance: across steps a velocity
  projection is left out where the next constrained drift projects those velocities again;
* with virtual sites (TIP4P), which the fused kernel places before each force evaluation and at the end of the step
  rather than after every drift: the sites sit on their rule and the trajectory is the plain one's;
* exact momentum, and the blow-up check naming the same first step;
* a System with a force that acts between steps (a CMMotionRemover) keeps every step at the step point: bit for bit;
* a periodic box whose atoms OpenMM reorders on the way.

On Reference and CPU the kernel is the plain reading whatever the setting: step(n) is n calls of step(1) bit for bit.
"""
import copy
import re

import numpy as np
import openmm as mm
import openmm.unit as unit
import pytest

from helpers import COMMON, positions_velocities, stiff_diatomic, tip4p_cluster, virtual_site_error
from openmm_symprk import SimulationBlowUpError, SymplecticIntegrator, plugin
from openmm_symprk.systems.forcegroups import split_forces

pytestmark = [pytest.mark.skipif(not plugin.available(), reason=f"native plugin unavailable: {plugin.unavailable_reason()}"),
              pytest.mark.filterwarnings("ignore::openmm_symprk.systems.checks.ConservationWarning")]
needs_common = pytest.mark.skipif(COMMON not in plugin.platforms(), reason=f"no native {COMMON} kernel here")

FUSE_NONE, FUSE_SEGMENTS, FUSE_ALL = 0, 1, 2
CALLS = (7, 13)  # two step() calls, the State read after each





def _scene(name, request):
    """(System, positions, velocities)."""
    if name == "tip4p":
        return tip4p_cluster(8, iterations=50, as_numpy=True)
    scene = request.getfixturevalue(name)
    return scene.system, scene.positions, scene.velocities


def _run(system, x, v, method, options, fusion, platform=COMMON, props=None, calls=CALLS):
    """[(positions, velocities) after each call], the integrator's own launches."""
    options = dict(options)
    if options.get("groups") == "split":
        system = mm.XmlSerializer.clone(system)
        options["groups"] = split_forces(system, slow="nonbonded" if system.getNumParticles() > 4 else
                                         ["CustomAngleForce", 2], substeps=2)
    ig = SymplecticIntegrator(1 * unit.femtoseconds, method, system=system, backend="native", **options)
    ig.setKernelFusion(fusion)
    if props is None:  # (one CPU thread: its force sums are then in a fixed order)
        props = {COMMON: {"Precision": "double"}, "CPU": {"Threads": "1"}}.get(platform, {})
    ctx = mm.Context(system, ig, mm.Platform.getPlatformByName(platform), props)
    ctx.setPositions(x)
    ctx.setVelocities(v)
    out = []
    for n in calls:
        ig.step(n)
        out.append(positions_velocities(ctx))
    launches = ig.getKernelLaunches()
    del ctx
    return out, launches


def _compare(a, b, bound):
    for (xa, va), (xb, vb) in zip(a, b):
        if bound == 0:
            np.testing.assert_array_equal(xa, xb)
            np.testing.assert_array_equal(va, vb)
        else:
            assert np.abs(xa - xb).max() <= bound, np.abs(xa - xb).max()
            assert np.abs(va - vb).max() <= 1e3 * bound, np.abs(va - vb).max()  # |v| / |x| ~ 1/fs here


#: CCMA stops within the relative tolerance (1e-5) of each constraint's length (0.15 nm here)
CCMA_BOUND = 1e-5 * 0.15
NVT = {"temperature": 300, "collision_time": 0.05, "random_seed": 9}

#: (scene, method, options, bound on |dx| in nm: 0 is bit for bit)
CASES = {
    "morse-verlet": ("morse", "verlet", {}, 0),
    "morse-yoshida4": ("morse", "yoshida-4", {}, 0),
    "morse-mts": ("morse", "verlet", {"groups": "split"}, 0),
    "morse-nvt-middle": ("morse", "omelyan-2", dict(NVT, thermostat_position="middle"), 0),
    "morse-nvt-ends-interval3": ("morse", "verlet", dict(NVT, thermostat_position="ends", thermostat_interval=3), 0),
    "morse-mts-nvt": ("morse", "verlet", dict(NVT, groups="split", thermostat_interval=2), 0),
    "morse-exact": ("morse", "verlet", {"exact_momentum": True}, 0),
    # SETTLE: the projections left out change the positions by round-off (double precision)
    "water8-verlet": ("water8", "verlet", {}, 1e-13),
    "water8-omelyan2": ("water8", "omelyan-2", {}, 1e-13),
    "water8-yoshida4": ("water8", "yoshida-4", {}, 1e-13),
    "water8-mts": ("water8", "verlet", {"groups": "split"}, 1e-13),
    "water8-nvt-middle": ("water8", "verlet", dict(NVT, thermostat_position="middle"), 1e-13),
    "water8-nvt-ends": ("water8", "verlet", dict(NVT, thermostat_position="ends"), 1e-13),
    "water8-nvt-ends-interval2": ("water8", "omelyan-2", dict(NVT, thermostat_position="ends", thermostat_interval=2),
                                  1e-13),
    "water8-exact": ("water8", "verlet", {"exact_momentum": True}, 1e-13),
    "water8-exact-nvt": ("water8", "verlet", dict(NVT, exact_momentum=True, thermostat_position="middle"), 1e-13),
    # CCMA, converged to its tolerance from another start where a projection was left out
    "constrained-pefrl": ("constrained", "pefrl", {}, CCMA_BOUND),
    "constrained-verlet-nvt": ("constrained", "verlet", dict(NVT, thermostat_position="middle"), CCMA_BOUND),
    # virtual sites (and SETTLE)
    "tip4p-yoshida4": ("tip4p", "yoshida-4", {}, 1e-13),
    "tip4p-nvt-middle": ("tip4p", "verlet", dict(NVT, thermostat_position="middle"), 1e-13),
}


@needs_common
@pytest.mark.parametrize("case", sorted(CASES))
def test_fused_execution_keeps_the_trajectory(case, request):
    scene, method, options, bound = CASES[case]
    system, x, v = _scene(scene, request)
    plain, plain_launches = _run(system, x, v, method, options, FUSE_NONE)
    for fusion in (FUSE_SEGMENTS, FUSE_ALL):
        fused, launches = _run(system, x, v, method, options, fusion)
        _compare(plain, fused, bound)
        assert launches < plain_launches  # (the counts per plan shape: tests/plugin/test_launch_counts.py)
    if scene == "tip4p":
        assert virtual_site_error(system, fused[-1][0]) < 1e-12


@needs_common
def test_the_atoms_reordered_on_the_way_keep_the_trajectory():
    """A periodic box with a cutoff: OpenMM reorders the atoms every 250 steps, which the fused kernel lets happen
    before the step's last force evaluation (where nothing is pending) rather than at the step's end; the two runs
    cross step 250 within one call and stay at SETTLE's round-off, grown by the dynamics (about 1e-11 nm here)."""
    from openmm_symprk.systems.prepare import maxwell_boltzmann, minimise
    from openmm_symprk.systems.scenes import water_box

    system, _, x = water_box("tip3p", box_nm=1.6, cutoff_nm=0.7)
    x = minimise(system, x, "Reference", tolerance=10.0, max_iterations=100)
    v = maxwell_boltzmann(system, x, 300.0, seed=2)
    options = dict(NVT, thermostat_position="middle")
    _compare(_run(system, x, v, "verlet", options, FUSE_NONE, calls=(270,))[0],
             _run(system, x, v, "verlet", options, FUSE_ALL, calls=(270,))[0], 1e-9)


@needs_common
@pytest.mark.parametrize("precision", ["mixed", "single"])
def test_fusion_in_mixed_and_single_precision(precision, request):
    """The same in the precisions users run: SETTLE's round-off, in the positions' precision, is the difference."""
    system, x, v = _scene("water8", request)
    props = {"Precision": precision}
    plain, _ = _run(system, x, v, "verlet", dict(NVT, thermostat_position="middle"), FUSE_NONE, props=props)
    fused, _ = _run(system, x, v, "verlet", dict(NVT, thermostat_position="middle"), FUSE_ALL, props=props)
    _compare(plain, fused, 1e-6 if precision == "mixed" else 1e-4)
    morse, mx, mv = _scene("morse", request)
    _compare(_run(morse, mx, mv, "yoshida-4", NVT, FUSE_NONE, props=props)[0],
             _run(morse, mx, mv, "yoshida-4", NVT, FUSE_ALL, props=props)[0], 0)


@needs_common
def test_a_force_acting_between_steps_keeps_every_step_at_the_step_point(request):
    """With a CMMotionRemover (which reads and changes the velocities at each step point) nothing is fused across
    steps: the fused run is the plain one bit for bit (the water's projections all run)."""
    system, x, v = _scene("water8", request)
    system = copy.deepcopy(system)
    system.addForce(mm.CMMotionRemover(1))
    plain, plain_launches = _run(system, x, v, "verlet", {}, FUSE_NONE)
    fused, launches = _run(system, x, v, "verlet", {}, FUSE_ALL)
    _compare(plain, fused, 0)
    # within the step only: a kick with the drift's delta, the apply, the closing kick (3 launches, not 4)
    assert launches == 3 * sum(CALLS) and plain_launches == 4 * sum(CALLS)


def _blow_up_step(platform, fusion, max_speed):
    """The step a blow-up of yoshida-4 beyond its stability limit is reported at."""
    system = stiff_diatomic()
    h = 1.7 / np.sqrt(2 * 1.0e5)  # h*omega = 1.7, beyond yoshida-4's stability limit 1.5734
    ig = SymplecticIntegrator(h, "yoshida-4", system=system, backend="native", max_speed=max_speed)
    ig.setKernelFusion(fusion)
    ctx = mm.Context(system, ig, mm.Platform.getPlatformByName(platform),
                     {"Precision": "double"} if platform == COMMON else {})
    ctx.setPositions([mm.Vec3(0, 0, 0), mm.Vec3(0.11, 0, 0)])
    with pytest.raises(SimulationBlowUpError) as info:
        ig.step(1000)
    del ctx
    return int(re.search(r"step (\d+)", str(info.value)).group(1))


@needs_common
def test_the_blow_up_names_the_same_first_step():
    """The last kick of a step checks the velocities before the next step's first kick adds to them in the same
    launch: the step named is the plain reading's and Reference's."""
    steps = {}
    for max_speed in (50.0, 1e4):
        steps[max_speed] = {fusion: _blow_up_step(COMMON, fusion, max_speed) for fusion in (FUSE_NONE, FUSE_ALL)}
        assert steps[max_speed][FUSE_ALL] == steps[max_speed][FUSE_NONE] == _blow_up_step("Reference", FUSE_ALL, max_speed)
    assert steps[50.0][FUSE_ALL] < steps[1e4][FUSE_ALL]


@pytest.mark.parametrize("platform", ["Reference", "CPU"])
@pytest.mark.parametrize("case", ["water8-nvt-middle", "morse-mts-nvt", "water8-exact"])
def test_reference_and_cpu_are_the_plain_reading(platform, case, request):
    """The host kernel runs the plan one operation at a time, every step ending at the step point: one call of n
    steps is n calls of one step, bit for bit, and the fusion setting changes nothing."""
    scene, method, options, _ = CASES[case]
    system, x, v = _scene(scene, request)
    whole, launches = _run(system, x, v, method, options, FUSE_ALL, platform, calls=(20,))
    single, _ = _run(system, x, v, method, options, FUSE_NONE, platform, calls=(1,) * 20)
    _compare(whole, single[-1:], 0)
    assert launches == 0


def test_the_fusion_setting_is_checked_and_kept(water8):
    ig = SymplecticIntegrator(1 * unit.femtoseconds, "verlet", system=water8.system, backend="native")
    assert ig.getKernelFusion() == ig.FuseAll == FUSE_ALL
    assert (ig.FuseNone, ig.FuseSegments) == (FUSE_NONE, FUSE_SEGMENTS)
    with pytest.raises(mm.OpenMMException, match="kernel fusion 3 is not one of"):
        ig.setKernelFusion(3)
    ig.setKernelFusion(FUSE_SEGMENTS)
    ctx = mm.Context(water8.system, ig, mm.Platform.getPlatformByName("Reference"))
    assert ig.getKernelFusion() == FUSE_SEGMENTS
    assert ig.getKernelFusionBlockAtoms() >= 1000  # the box runs its events in one block
    del ctx
