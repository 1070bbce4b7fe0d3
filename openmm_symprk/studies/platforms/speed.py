"""Benchmark of the native backend against OpenMM's VerletIntegrator and the CustomIntegrator path.

    symprk speed            # CPU platform, both systems (a few minutes)
    symprk speed --quick    # fewer steps

Prints, per system, the time per step of OpenMM's VerletIntegrator and, for each method, of the native
integrator and of the CustomIntegrator (``openmm_symprk.SymplecticIntegrator``), with the ratios

    verlet:       t_native / t_VerletIntegrator                          (target <= 0.9)
    higher order: t_native / (force evaluations per step * t_VerletIntegrator)   (target <= 1)

Systems: a rigid TIP3P water cluster in vacuum (no cutoff) and a periodic rigid TIP3P water box of about
6,000 atoms (app.Modeller.addSolvent, PME, 1 nm cutoff).  Each timing is the best of ``--repeats`` runs
of ``--steps`` steps after a warm-up, the integrators interleaved so that machine noise hits all alike.
Not a test: nothing is asserted.
"""
from __future__ import annotations

import argparse

import openmm as mm

from ..core.engine import RowEngine
from ..core.rows import Row
from ..core.timing import time_rows
from ...support.errors import InputError

DEFAULT_METHODS = ("verlet", "omelyan-2", "yoshida-4", "blanes-moan-srkn6b-4", "kahan-li-6")


def water_cluster_system(n_waters: int):
    """(title, System, positions, velocities): a rigid water cluster in vacuum, minimised."""
    from ...systems.scenes import water_cluster

    sc = water_cluster(n_waters, minimize=True)
    return f"rigid water cluster, vacuum, {sc.n_atoms} atoms", sc.system, sc.positions, sc.velocities


def water_box_system(box_nm: float = 3.9):
    """(title, System, positions, velocities): a periodic rigid TIP3P box (about 6,000 atoms at 3.9 nm; Modeller's
    water, PME, 1 nm cutoff), minimised, velocities at 300 K."""
    from ...systems.prepare import maxwell_boltzmann, minimise
    from ...systems.scenes import water_box

    system, _, x = water_box("tip3p", box_nm=box_nm, cutoff_nm=1.0)
    pos = minimise(system, x, "CPU", tolerance=10.0, max_iterations=200)
    vel = maxwell_boltzmann(system, pos, 300.0, seed=7)
    return f"rigid TIP3P water box, PME 1 nm, {system.getNumParticles()} atoms", system, pos, vel


def measure(system, pos, vel, methods, platform="CPU", steps=100, repeats=3, dt_fs=2.0, custom=True) -> dict:
    """Seconds per step (fastest block, rows in turns: :func:`..core.timing.time_rows`) of every integrator; keys
    'openmm-verlet', 'native:<m>', 'custom:<m>'.  ``platform``: NAME or NAME:PRECISION."""
    from ...integrators import native_available

    backends = (["native"] if native_available() else []) + (["custom"] if custom else [])
    rows = {"openmm-verlet": Row("openmm-verlet", dt_fs)}
    rows.update({f"{b}:{m}": Row(m, dt_fs, backend=b) for m in methods for b in backends})
    engines = {k: RowEngine(row, system, pos, vel, platform=platform, threads=None, start=False, quiet=False)
               for k, row in rows.items()}
    return {k: t.best for k, t in time_rows(engines, steps, repeats, warmup=3).items()}


def format_table(title, best, methods, constraints: bool = True) -> str:
    base = best["openmm-verlet"]
    lines = [title, f"  OpenMM VerletIntegrator: {base * 1e3:.3f} ms/step",
             f"  {'method':22s} {'f/step':>6s} {'native ms':>10s} {'native ratio':>12s} {'custom ms':>10s} {'custom ratio':>12s}"]
    for m in methods:
        fe = Row(m, 1.0).evals_per_step(constraints)
        nat = best.get(f"native:{m}")
        cus = best.get(f"custom:{m}")
        row = f"  {m:22s} {fe:6d} "
        row += f"{nat * 1e3:10.3f} {nat / (fe * base):12.3f} " if nat is not None else f"{'-':>10s} {'-':>12s} "
        row += f"{cus * 1e3:10.3f} {cus / (fe * base):12.3f}" if cus is not None else f"{'-':>10s} {'-':>12s}"
        lines.append(row)
    lines.append("  ratio = time per step / (force evaluations per step x VerletIntegrator time per step)")
    return "\n".join(lines)


def build_parser(prog: str = "symprk speed"):
    ap = argparse.ArgumentParser(prog=prog, description=__doc__.split("\n\n")[0])
    ap.add_argument("--platform", default="CPU")
    ap.add_argument("--precision", default=None, help="OpenCL/CUDA precision property (single, mixed, double)")
    ap.add_argument("--methods", default=",".join(DEFAULT_METHODS))
    ap.add_argument("--cluster-waters", type=int, default=216)
    ap.add_argument("--box-nm", type=float, default=3.9, help="edge of the PME water box (3.9 nm: ~6,000 atoms)")
    ap.add_argument("--steps", type=int, default=None)
    ap.add_argument("--repeats", type=int, default=3)
    ap.add_argument("--systems", default="cluster,box")
    ap.add_argument("--no-custom", action="store_true", help="skip the CustomIntegrator timings")
    ap.add_argument("--quick", action="store_true", help="fewer steps and repeats (a rough look)")
    ap.add_argument("--no-forces", action="store_true",
                    help="remove every force (constraints stay): times the integrators' own work alone")
    return ap


def run(args):
    from ... import plugin

    if not plugin.available():
        raise plugin.NativeUnavailableError(f"the native backend is unavailable: {plugin.unavailable_reason()}")
    if args.platform not in plugin.platforms():
        raise InputError(f"--platform {args.platform}: no native kernel for it (have: {', '.join(plugin.platforms())})")
    methods = [m.strip() for m in args.methods.split(",") if m.strip()]
    platform = f"{args.platform}:{args.precision}" if args.precision else args.platform
    import os

    print(f"load average before: {os.getloadavg()[0]:.2f} (other processes on this machine skew every timing)")
    print(f"openmm {mm.version.full_version}, platform {platform}, "
          f"threads: {mm.Platform.getPlatformByName(args.platform).getPropertyDefaultValue('Threads') if args.platform == 'CPU' else '-'}")
    for which in args.systems.split(","):
        if which == "cluster":
            title, system, pos, vel = water_cluster_system(args.cluster_waters)
            steps = args.steps or (50 if args.quick else 200)
        elif which == "box":
            title, system, pos, vel = water_box_system(args.box_nm)
            steps = args.steps or (20 if args.quick else 100)
        else:
            raise InputError(f"--systems: unknown system {which!r}; known: cluster, box")
        if args.no_forces:
            while system.getNumForces():
                system.removeForce(0)
            title += ", no forces (integrator work only)"
        best = measure(system, pos, vel, methods, platform, steps=steps, repeats=1 if args.quick else args.repeats,
                       custom=not args.no_custom)
        print(format_table(f"{title}: {steps} steps x best of {1 if args.quick else args.repeats}", best, methods,
                           system.getNumConstraints() > 0))
    print(f"load average after: {os.getloadavg()[0]:.2f}")
