"""The GPU check: the native backend on OpenMM's CUDA platform, in one command.

    symprk gpucheck          # mixed and double precision
    symprk gpucheck --quick  # fewer steps, the PME box only

Needs OpenMM's CUDA platform (``pip install "openmm_symprk[cuda12]"`` and an NVIDIA GPU with its driver).
For mixed and double precision it prints, as markdown tables:

1. the same program on both backends: max |x_native - x_custom| and |v_native - v_custom| after 200 steps
   of ``verlet`` and ``yoshida-4`` (rigid-water cluster, SETTLE; villin in vacuum, HBonds: CCMA/SHAKE), the native
   kernel as the plain reading of the plan and fused (:func:`same_program`);
2. conservation: |dL|/|L| and |dP| after 2,000 steps of ``verlet`` on the cluster, with and without
   ``exact_momentum`` (:mod:`.conservation`'s table);
3. speed: time per step of the native ``verlet``, ``omelyan-2`` and ``yoshida-4`` against OpenMM's
   VerletIntegrator, and of the same with the thermostat (SVR, middle) against OpenMM's LangevinMiddleIntegrator
   (ratio per force evaluation, integrators taking turns: :mod:`.speed`'s table, with the plugin's own launches and
   host copies per step) on a periodic rigid TIP3P box with PME and on villin solvated to about 21,000 atoms (PME,
   HBonds, rigid water).

Without a CUDA platform it says why in one line and exits with status 2.  Not a test: nothing is asserted.
"""
from __future__ import annotations

import argparse
import warnings

import numpy as np
import openmm as mm
import openmm.app as app
import openmm.unit as unit

from ..core.engine import RowEngine
from ..core.rows import Row
from . import conservation, speed

#: The methods of the speed table (each also with the thermostat).
SPEED_METHODS = ("verlet", "omelyan-2", "yoshida-4")


def cuda_unavailable_reason() -> str:
    """'' when OpenMM's CUDA platform and the native CUDA kernel are both usable here, else why not."""
    from ... import plugin

    try:
        mm.Platform.getPlatformByName("CUDA")
    except Exception:
        failures = [f for f in mm.Platform.getPluginLoadFailures() if "CUDA" in f]
        why = failures[0].strip() if failures else "the openmm-cuda-12 package is not installed"
        return f"OpenMM has no CUDA platform here ({why}); install openmm_symprk[cuda12] on a machine with a GPU"
    how = plugin.details().get("CUDA", "")
    return "" if how == "native" else f"the native plugin has no CUDA kernel: {how}"


def _solvated_villin(n_target: int, seed: int = 7):
    """(title, System, positions, velocities): villin solvated to about ``n_target`` atoms (PME, HBonds, rigid
    water), minimised on CUDA."""
    from ...systems.prepare import maxwell_boltzmann, minimise
    from ...systems.scenes import openmm_data

    pdb = app.PDBFile(openmm_data("test.pdb"))
    ff = app.ForceField("amber14-all.xml", "amber14/tip3p.xml")
    mod = app.Modeller(pdb.topology, pdb.positions)
    mod.deleteWater()
    side = (n_target / 100.0) ** (1 / 3)  # ~33 waters, ~100 atoms, per nm^3 at ~1 g/cm^3
    mod.addSolvent(ff, boxSize=mm.Vec3(side, side, side) * unit.nanometer, neutralize=True)
    system = ff.createSystem(mod.topology, nonbondedMethod=app.PME, nonbondedCutoff=0.9 * unit.nanometer,
                             constraints=app.HBonds, rigidWater=True, removeCMMotion=False)
    pos = minimise(system, mod.positions, "CUDA", tolerance=10.0, max_iterations=200)
    return (f"villin in water, PME, {system.getNumParticles()} atoms", system, pos,
            maxwell_boltzmann(system, pos, 300.0, seed))


def same_program(scenes, precisions, steps):
    """max |x_native - x_custom| and |v_native - v_custom| after ``steps`` steps, the native kernel run as the plain
    reading of the plan (FuseNone: the CustomIntegrator program operation for operation) and fused (the default,
    which leaves out velocity projections a constrained drift makes good to the constraint tolerance)."""
    rows = ["| scene | precision | method | plain: max abs(dx) nm | max abs(dv) nm/ps | fused: max abs(dx) nm | "
            "max abs(dv) nm/ps |", "|---|---|---|---|---|---|---|"]
    for scene in scenes:
        for prec in precisions:
            for method in ("verlet", "yoshida-4"):
                out = {}
                for key, backend, fusion in (("plain", "native", 0), ("fused", "native", None), ("custom", "custom", None)):
                    eng = RowEngine(Row(method, 1.0, backend=backend), scene, platform=f"CUDA:{prec}", start=False,
                                    quiet=False)
                    if fusion is not None:
                        eng.integrator.setKernelFusion(fusion)
                    eng.step(steps)
                    out[key] = eng.sample(energy=False)
                    del eng
                cells = []
                for key in ("plain", "fused"):
                    cells += [f"{float(np.abs(out[key].x - out['custom'].x).max()):.1e}",
                              f"{float(np.abs(out[key].v - out['custom'].v).max()):.1e}"]
                rows.append(f"| {scene.name} | {prec} | {method} | " + " | ".join(cells) + " |")
    return "\n".join(rows)


def build_parser(prog: str = "symprk gpucheck"):
    p = argparse.ArgumentParser(prog=prog, description=__doc__.split("\n\n")[0])
    p.add_argument("--quick", action="store_true", help="fewer steps; the PME box only for speed")
    p.add_argument("--precisions", default="mixed,double",
                   help="comma-separated CUDA precisions to check (default: mixed,double)")
    return p


def run(args):
    from ...plugin import NativeUnavailableError

    reason = cuda_unavailable_reason()
    if reason:
        raise NativeUnavailableError(reason)
    warnings.simplefilter("ignore")
    from ...systems.scenes import protein_vacuum, water_cluster

    precisions = [s for s in args.precisions.split(",") if s]
    cluster = water_cluster(27)
    print(f"OpenMM {mm.version.full_version}, CUDA device: "
          f"{mm.Platform.getPlatformByName('CUDA').getPropertyDefaultValue('DeviceName') or 'default'}\n")
    print("Same program on both backends (200 steps of 1 fs):\n")
    print(same_program([cluster] + ([] if args.quick else [protein_vacuum()]), precisions, 50 if args.quick else 200))
    print("\nConservation, native verlet, 27-water cluster, 2 fs (off/on: exact_momentum):\n")
    print(conservation.table([conservation.compare(cluster, f"CUDA:{p}", "verlet", 500 if args.quick else 2000,
                                                   backend="native") for p in precisions]))
    boxes = [speed.water_box_system(3.9)] + ([] if args.quick else [_solvated_villin(23000)])  # about 21,000 atoms
    print("\nSpeed (fastest of the blocks, integrators taking turns):\n")
    for title, system, pos, vel in boxes:
        for p in precisions:
            results = speed.measure(system, pos, vel, SPEED_METHODS, f"CUDA:{p}", 50 if args.quick else 300,
                                    2 if args.quick else 4, custom=False, thermostat=True)
            print(speed.format_table(f"{title}, CUDA {p}", results, SPEED_METHODS, system.getNumConstraints() > 0,
                                     thermostat=True))
