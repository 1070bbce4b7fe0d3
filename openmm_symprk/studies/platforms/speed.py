"""Benchmark of the native backend against OpenMM's VerletIntegrator and the CustomIntegrator path.

    symprk speed            # CPU platform, both systems (a few minutes)
    symprk speed --quick    # fewer steps
    symprk speed --platform OpenCL --precision mixed --thermostat    # with the counts of device work

Prints, per system, the time per step of OpenMM's VerletIntegrator and, for each method, of the native
integrator and of the CustomIntegrator (``openmm_symprk.SymplecticIntegrator``), with the ratios

    verlet:       t_native / t_VerletIntegrator                          (target <= 0.9)
    higher order: t_native / (force evaluations per step * t_VerletIntegrator)   (target <= 1)

With ``--thermostat`` each method also runs with the package's thermostat (SVR, collision time 0.1 ps, in the middle
of the step), against OpenMM's LangevinMiddleIntegrator (friction 1/ps).

Systems: a rigid TIP3P water cluster in vacuum (no cutoff) and a periodic rigid TIP3P water box of about
6,000 atoms (app.Modeller.addSolvent, PME, 1 nm cutoff).  Each timing is the best of ``--repeats`` runs
of ``--steps`` steps after a warm-up, the integrators interleaved so that machine noise hits all alike.

On a device platform (OpenCL, CUDA) the table also gives, per step of one ``step(steps)`` call after the timing,
the device launches and host copies: every row's, counted by the OpenCL/CUDA API intercept where the process runs with
it (``python tools/count_launches.py --exec symprk speed ...``), else the native rows' own
(``device_counts()``: the plugin's kernels and transfers, not OpenMM's force and constraint kernels).
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


#: The counters of the launch intercept (tools/launch_intercept.cpp), in the order its symprk_intercept_count numbers them.
INTERCEPT_COUNTERS = ("kernels", "device_copies", "fills", "reads", "writes", "maps")


def intercept():
    """The OpenCL/CUDA API intercept (tools/launch_intercept.cpp) when this process runs with it preloaded, else None."""
    import ctypes

    try:
        lib = ctypes.CDLL(None)
        lib.symprk_intercept_count.restype = ctypes.c_longlong
        return lib
    except AttributeError:
        return None


def intercept_counts(lib) -> dict:
    """The intercept's counts since its last reset ({counter: n}, and "per_kernel": {kernel name: launches})."""
    import ctypes

    counts = {name: int(lib.symprk_intercept_count(i)) for i, name in enumerate(INTERCEPT_COUNTERS)}
    size = lib.symprk_intercept_kernels(None, 0)
    text = ctypes.create_string_buffer(size)
    lib.symprk_intercept_kernels(text, size)
    counts["per_kernel"] = {line.rsplit(" ", 1)[0]: int(line.rsplit(" ", 1)[1])
                            for line in text.value.decode().splitlines() if line}
    return counts


def launches(counts: dict) -> int:
    """Device launches of intercept counts: kernels, device-side copies and fills."""
    return counts["kernels"] + counts["device_copies"] + counts["fills"]


def host_copies(counts: dict) -> int:
    """Host transfers of intercept counts: reads, writes and maps."""
    return counts["reads"] + counts["writes"] + counts["maps"]


def count_step(integrator, steps: int, lib=None) -> dict:
    """Device work per step of one ``integrator.step(steps)`` call: {"launches", "copies"} counted by the intercept
    ``lib`` (None: not counted), {"own_launches", "own_copies"} the plugin's own (a native integrator)."""
    out = {}
    native = hasattr(integrator, "device_counts")
    if native:
        own = integrator.device_counts()
    if lib is not None:
        lib.symprk_intercept_reset()
    integrator.step(steps)
    if lib is not None:
        counts = intercept_counts(lib)
        out.update(launches=launches(counts) / steps, copies=host_copies(counts) / steps)
    if native:
        after = integrator.device_counts()
        out.update(own_launches=(after[0] - own[0]) / steps, own_copies=(after[1] - own[1]) / steps)
    return out


#: The thermostat rows' settings (--thermostat): the package's SVR and OpenMM's LangevinMiddleIntegrator.
THERMOSTAT_TAU_PS = 0.1
LANGEVIN_FRICTION_PER_PS = 1.0


def row_set(methods, backends, thermostat: bool, dt_fs: float) -> dict:
    """{key: Row} of a measurement: 'openmm-verlet', 'openmm-langevin' (thermostat), '<backend>:<method>' and
    '<backend>:<method>:nvt' (thermostat)."""
    rows = {"openmm-verlet": Row("openmm-verlet", dt_fs)}
    if thermostat:
        rows["openmm-langevin"] = Row("langevin", dt_fs, friction_per_ps=LANGEVIN_FRICTION_PER_PS)
    for m in methods:
        for b in backends:
            rows[f"{b}:{m}"] = Row(m, dt_fs, backend=b)
            if thermostat:
                rows[f"{b}:{m}:nvt"] = Row(m, dt_fs, backend=b, tau_ps=THERMOSTAT_TAU_PS, position="auto")
    return rows


def measure(system, pos, vel, methods, platform="CPU", steps=100, repeats=3, dt_fs=2.0, custom=True,
            thermostat=False) -> dict:
    """{key: {"seconds": per step, and on a device platform the counts of :func:`count_step`}} of every integrator:
    seconds per step the fastest block, rows in turns (:func:`..core.timing.time_rows`); keys of :func:`row_set`.
    ``platform``: NAME or NAME:PRECISION."""
    from ...integrators import native_available

    backends = (["native"] if native_available() else []) + (["custom"] if custom else [])
    rows = row_set(methods, backends, thermostat, dt_fs)
    engines = {k: RowEngine(row, system, pos, vel, platform=platform, threads=None, start=False, quiet=False)
               for k, row in rows.items()}
    out = {k: {"seconds": t.best} for k, t in time_rows(engines, steps, repeats, warmup=3).items()}
    if platform.split(":")[0] not in ("CPU", "Reference"):
        lib = intercept()
        for k, engine in engines.items():
            out[k].update(count_step(engine.integrator, steps, lib))
    return out


def _counts(entry) -> str:
    """The count columns of one row: launches and copies per step (every row's with the intercept, else the native
    rows' own, marked so)."""
    if "launches" in entry:
        return f" {entry['launches']:9.2f} {entry['copies']:7.2f}"
    if "own_launches" in entry:
        return f" {entry['own_launches']:8.2f}* {entry['own_copies']:6.2f}*"
    return f" {'-':>9s} {'-':>7s}"


def format_table(title, results, methods, constraints: bool = True, thermostat: bool = False) -> str:
    counted = any("launches" in e or "own_launches" in e for e in results.values())
    count_head = f" {'launches':>9s} {'copies':>7s}" if counted else ""
    lines = [title]
    bases = [("openmm-verlet", "OpenMM VerletIntegrator", "")]
    if thermostat:
        bases.append(("openmm-langevin", "OpenMM LangevinMiddleIntegrator", ":nvt"))
    for key, name, _ in bases:
        entry = results[key]
        lines.append(f"  {name}: {entry['seconds'] * 1e3:.3f} ms/step" +
                     (f", {entry['launches']:.2f} launches and {entry['copies']:.2f} host copies per step"
                      if "launches" in entry else ""))
    lines.append(f"  {'method':26s} {'f/step':>6s} {'native ms':>10s} {'native ratio':>12s}{count_head} "
                 f"{'custom ms':>10s} {'custom ratio':>12s}")
    for key, name, suffix in bases:
        base = results[key]["seconds"]
        for m in methods:
            fe = Row(m, 1.0).evals_per_step(constraints)
            nat = results.get(f"native:{m}{suffix}")
            cus = results.get(f"custom:{m}{suffix}")
            row = f"  {m + (' SVR' if suffix else ''):26s} {fe:6d} "
            row += (f"{nat['seconds'] * 1e3:10.3f} {nat['seconds'] / (fe * base):12.3f}" if nat is not None
                    else f"{'-':>10s} {'-':>12s}")
            if counted:
                row += _counts(nat) if nat is not None else f" {'-':>9s} {'-':>7s}"
            row += (f" {cus['seconds'] * 1e3:10.3f} {cus['seconds'] / (fe * base):12.3f}" if cus is not None
                    else f" {'-':>10s} {'-':>12s}")
            lines.append(row)
    lines.append("  ratio = time per step / (force evaluations per step x VerletIntegrator time per step"
                 + (", LangevinMiddleIntegrator's for the SVR rows)" if thermostat else ")"))
    if counted:
        lines.append("  launches, copies: device launches and host copies per step of one call" +
                     (" (*: the plugin's own only; run under tools/count_launches.py --exec for every kernel)"
                      if not any("launches" in e for e in results.values()) else ""))
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
    ap.add_argument("--thermostat", action="store_true",
                    help="also each method with the thermostat (SVR, middle), against OpenMM's LangevinMiddleIntegrator")
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
        results = measure(system, pos, vel, methods, platform, steps=steps, repeats=1 if args.quick else args.repeats,
                          custom=not args.no_custom, thermostat=args.thermostat)
        print(format_table(f"{title}: {steps} steps x best of {1 if args.quick else args.repeats}", results, methods,
                           system.getNumConstraints() > 0, args.thermostat))
    print(f"load average after: {os.getloadavg()[0]:.2f}")
