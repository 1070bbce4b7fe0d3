"""Device launches and host copies of a step on the Common platforms (OpenCL here, PoCL).

1. The plugin's own launches (``getKernelLaunches``: its kernels and device copies, not OpenMM's constraint, force and
   random-number kernels), per step and per step() call, for each plan shape, with each kernel fusion: the numbers
   the plan implies, derived below (the 8-water cluster: SETTLE, no cutoff, so the atoms are never reordered).
2. Every launch and host copy of a step, counted by an intercept of the OpenCL API (tools/count_launches.py, built
   with g++ and preloaded into a subprocess), on the 2.2 nm TIP3P box (PME, SETTLE, mixed precision; 100 steps in one
   call after 10, and the same 100 in four calls), against OpenMM's VerletIntegrator and LangevinMiddleIntegrator on
   the same Context set-up: native verlet costs VerletIntegrator's launches per step, with the thermostat at most
   LangevinMiddleIntegrator's, omelyan-2 at most 1.1x VerletIntegrator's per force evaluation, and host copies per
   step OpenMM's; each step() call adds the closing kick and velocity projection that bring the velocities to the step
   point, and the reads of the blow-up record (and the thermostat's skipped events).
"""
import json
import os
import shutil
import subprocess
import sys
from pathlib import Path

import openmm as mm
import openmm.unit as unit
import pytest

from helpers import COMMON
from openmm_symprk import SymplecticIntegrator, plugin
from openmm_symprk.systems.forcegroups import split_forces

pytestmark = [pytest.mark.skipif(not plugin.available(), reason=f"native plugin unavailable: {plugin.unavailable_reason()}"),
              pytest.mark.skipif(COMMON not in plugin.platforms(), reason=f"no native {COMMON} kernel here"),
              pytest.mark.filterwarnings("ignore::openmm_symprk.systems.checks.ConservationWarning")]

ROOT = Path(__file__).resolve().parents[2]
NVT = {"temperature": 300, "random_seed": 3}

#: shape -> (method, options, {fusion: (own launches per step, per call)}); with constraints (SETTLE).
#: FuseNone: a launch per per-atom operation (kick, drift delta, drift apply, event apply, ...) and per block reduction
#: (exact-momentum projection and rigid sums, event sums) and device copy (multiple time stepping's group forces).
#: FuseAll/FuseSegments: a launch per segment between the constraints, force evaluations and reductions; the last
#: kick of a step joins the next step's first kick and drift delta (nothing acts between steps here), so each call adds
#: one launch, the closing kick (with exact momentum also the projection's save and rigid correction).
SHAPES = {
    # [K][D][A][K] / [K+K+D][A]
    "verlet": ("verlet", {}, {0: (4, 0), 1: (2, 1), 2: (2, 1)}),
    # the middle placement's step runs from its closing kick (kick 1, drift 1/2, event, drift 1/2: the State holds the
    # thermostat point's velocities), so a call ends on a drift and adds nothing:
    # [K][D][A] [E][EA] [D][A] / [K+D][A] [E] [EA+D][A] / [K+D] [A+E+EA+D in one block] [A]
    "verlet-nvt-middle": ("verlet", dict(NVT, thermostat_position="middle"), {0: (7, 0), 1: (5, 0), 2: (3, 0)}),
    # [E][EA][K][D][A][K] [E][EA] / [E] [EA+K+D][A][K] [E] [EA] / [E+EA+K+D][A][K][E+EA]: the events run every step, so
    # the kicks are not joined across steps
    "verlet-nvt-ends": ("verlet", dict(NVT, thermostat_position="ends"), {0: (8, 0), 1: (6, 0), 2: (4, 0)}),
    # [K][D][A][K][D][A][K] / [K+K+D][A][K+D][A]
    "omelyan-2": ("omelyan-2", {}, {0: (7, 0), 1: (4, 1), 2: (4, 1)}),
    # [Ks][Kf][D][A] c [Kf][D][A] c [Kf] c [Ks] (c: a group's force copy, after each evaluation) /
    # [Ks+Ks+Kf+D][A] [Kf+D][A] [Kf] c (fused, the fast forces are copied only before the slow evaluation overwrites
    # them: the next step's first fast kick reuses them)
    "mts": ("verlet", {"groups": "split"}, {0: (12, 0), 1: (6, 1), 2: (6, 1)}),
    # p[K][D] r[A] p[K] [S] r[R] / p[K+K+D] r[A], per call [K+S] r[R] (p: projection, r: rigid sums, S: save, R: apply)
    "exact-momentum": ("verlet", {"exact_momentum": True}, {0: (10, 0), 1: (4, 3), 2: (4, 3)}),
}


def _own_launches(water8, method, options, fusion):
    """(own launches per step, per call): from a call of 5 steps and one of 25."""
    system = water8.system
    options = dict(options)
    if options.get("groups") == "split":
        system = mm.XmlSerializer.clone(system)
        options["groups"] = split_forces(system, "nonbonded", 2)
    ig = SymplecticIntegrator(1 * unit.femtoseconds, method, system=system, backend="native", **options)
    ig.setKernelFusion(fusion)
    ctx = mm.Context(system, ig, mm.Platform.getPlatformByName(COMMON), {"Precision": "double"})
    ctx.setPositions(water8.positions)
    ctx.setVelocities(water8.velocities)
    ig.step(2)
    counts = []
    for n in (5, 25):
        before = ig.getKernelLaunches()
        ig.step(n)
        counts.append(ig.getKernelLaunches() - before)
    del ctx
    per_step = (counts[1] - counts[0]) / 20
    return per_step, counts[0] - 5 * per_step


@pytest.mark.parametrize("shape", sorted(SHAPES))
def test_own_launches_per_step_for_each_plan_shape(shape, water8):
    method, options, expected = SHAPES[shape]
    for fusion, (per_step, per_call) in expected.items():
        assert _own_launches(water8, method, options, fusion) == (per_step, per_call), (shape, fusion)


def test_reference_makes_no_launches(water8):
    ig = SymplecticIntegrator(1 * unit.femtoseconds, "verlet", system=water8.system, backend="native")
    ctx = mm.Context(water8.system, ig, mm.Platform.getPlatformByName("Reference"))
    ctx.setPositions(water8.positions)
    ig.step(3)
    assert ig.getKernelLaunches() == 0 and ig.getHostTransfers() == 0
    del ctx


# -- every launch, counted by the OpenCL API intercept, against OpenMM's integrators ------------------------------------
@pytest.fixture(scope="module")
def counted(tmp_path_factory):
    """tools/count_launches.py's rows on the issue's box ({key: row})."""
    if shutil.which(os.environ.get("CXX", "g++")) is None:
        pytest.skip("no C++ compiler to build the OpenCL intercept")
    out = tmp_path_factory.mktemp("launches")
    result = subprocess.run([sys.executable, str(ROOT / "tools" / "count_launches.py"), "--platform", COMMON,
                             "--precision", "mixed", "--box-nm", "2.2", "--warmup", "10", "--steps", "100",
                             "--calls", "4", "--only", "openmm-verlet,openmm-langevin,verlet,verlet-nvt,omelyan-2",
                             "--json", str(out / "counts.json"), "--build-dir", str(out / "build")],
                            capture_output=True, text=True, timeout=1800)
    assert result.returncode == 0, result.stdout[-3000:] + result.stderr[-3000:]
    return {row["key"]: row for row in json.loads((out / "counts.json").read_text())["rows"]}


def test_the_intercept_sees_openmms_integrators_and_the_plugins_kernels(counted):
    """The control: OpenMM's integrators launch their own kernels and the force kernels every step; the native rows
    launch the plugin's, and no OpenMM integration kernel."""
    verlet = counted["openmm-verlet"]["one_call"]["per_kernel"]
    assert verlet["integrateVerletPart1"] == verlet["integrateVerletPart2"] == 100
    assert counted["openmm-langevin"]["one_call"]["per_kernel"]["integrateLangevinMiddlePart3"] == 100
    native = counted["verlet"]["one_call"]["per_kernel"]
    assert native["symprkSegment"] == counted["verlet"]["one_call"]["own_launches"] == 201
    assert not any(name.startswith("integrate") for name in native)
    # the force evaluation's kernels are the same ones, as often
    forces = {k: v for k, v in verlet.items() if not k.startswith(("integrate", "applySettle"))}
    assert {k: native.get(k) for k in forces} == forces


def test_native_verlet_launches_no_more_per_step_than_verlet_integrator(counted):
    verlet, native = counted["openmm-verlet"], counted["verlet"]
    assert native["launches_per_step_beyond_calls"] <= verlet["launches_per_step_beyond_calls"]
    # what a call adds: the closing kick and the velocity projection (SETTLE) at the call's end
    assert native["launches_per_call"] == verlet["launches_per_call"] + 2
    assert native["launches_per_step"] <= verlet["launches_per_step"] + 2 / 100


def test_the_thermostat_launches_no_more_per_step_than_langevin_middle(counted):
    langevin, native = counted["openmm-langevin"], counted["verlet-nvt"]
    assert native["launches_per_step"] <= langevin["launches_per_step"]
    assert native["launches_per_step_beyond_calls"] <= langevin["launches_per_step_beyond_calls"]
    assert native["one_call"]["per_kernel"]["symprkEventBlock"] == 100  # the event and its neighbours: one launch


def test_omelyan2_launches_per_force_evaluation_within_a_tenth_of_verlet_integrators(counted):
    verlet, native = counted["openmm-verlet"], counted["omelyan-2"]
    assert native["force_evaluations"] == 2
    assert native["launches_per_step"] / 2 <= 1.1 * verlet["launches_per_step"]
    assert native["launches_per_step_beyond_calls"] / 2 <= verlet["launches_per_step_beyond_calls"]


def test_host_copies_per_step_are_openmms(counted):
    """A step copies what OpenMM's force evaluation copies (its neighbour-list size check) and nothing more; each call
    reads the blow-up record (and, with the thermostat, the skipped-event count) once."""
    for key, reads in (("verlet", 1), ("verlet-nvt", 2), ("omelyan-2", 1)):
        openmm_row = counted["openmm-langevin" if key == "verlet-nvt" else "openmm-verlet"]
        row = counted[key]
        per_eval = row["copies_per_step_beyond_calls"] / row["force_evaluations"]
        assert per_eval <= openmm_row["copies_per_step_beyond_calls"], key
        assert row["copies_per_call"] == openmm_row["copies_per_call"] + reads, key
