#!/usr/bin/env python3
"""Count what a step asks of the device: kernel launches and host transfers per step of OpenMM's VerletIntegrator and
LangevinMiddleIntegrator and of the native integrator's plan shapes, each on the same Context set-up.

    python tools/count_launches.py                  # a 2.2 nm TIP3P box, PME, HBonds, OpenCL mixed: the table
    python tools/count_launches.py --kernels        # and each integrator's launches per kernel name
    python tools/count_launches.py --json out.json  # the numbers as JSON (tests/plugin/test_launch_counts.py)
    python tools/count_launches.py --exec symprk speed --platform OpenCL ...   # any command, counted

It compiles tools/launch_intercept.cpp with g++ (into build/launch-intercept/, or --build-dir) and runs itself (or the
--exec command) again with that library preloaded (LD_PRELOAD): every clEnqueueNDRangeKernel, device-side copy and
fill counts as a launch, every clEnqueueReadBuffer, WriteBuffer and MapBuffer as a host copy (on CUDA: cuLaunchKernel,
cuMemcpy*).  For each integrator: a Context, ``step(warmup)``, then the counts of one ``step(steps)`` call per step
(the issue's measure), and of ``calls`` calls of ``steps // calls`` steps (the same steps, so that work OpenMM does
every few steps falls alike), whose difference gives the cost of a call apart from the cost of a step.  The native
rows also show the plugin's own launches per step (``device_counts()``: its kernels alone).
"""
from __future__ import annotations

import argparse
import json
import os
import subprocess
import sys
from pathlib import Path

HERE = Path(__file__).resolve().parent
SOURCE = HERE / "launch_intercept.cpp"
def build(out_dir: Path) -> Path:
    """Compile the intercept library into out_dir (again only when the source is newer); its path."""
    out_dir.mkdir(parents=True, exist_ok=True)
    lib = out_dir / "launch_intercept.so"
    if not lib.exists() or lib.stat().st_mtime < SOURCE.stat().st_mtime:
        subprocess.run([os.environ.get("CXX", "g++"), "-O2", "-shared", "-fPIC", "-o", str(lib), str(SOURCE), "-ldl"],
                       check=True)
    return lib


def water_box(box_nm: float):
    """(System, positions, velocities): the rigid TIP3P box of ``symprk speed`` (PME, 1 nm cutoff, SETTLE; no
    CMMotionRemover), minimised, velocities at 300 K."""
    from openmm_symprk.studies.platforms.speed import water_box_system

    _, system, pos, vel = water_box_system(box_nm)
    return system, pos, vel


def integrators(system):
    """[(key, name, force evaluations per step, factory(system) -> (system, integrator))]."""
    import openmm as mm
    import openmm.unit as unit

    from openmm_symprk import SymplecticIntegrator
    from openmm_symprk.systems.forcegroups import split_forces

    dt = 2 * unit.femtoseconds

    def native(method="verlet", **options):
        return lambda s: (s, SymplecticIntegrator(dt, method, system=s, backend="native", **options))

    def mts(s):
        s = mm.XmlSerializer.clone(s)
        groups = split_forces(s, "reciprocal", 2)
        return s, SymplecticIntegrator(dt, "verlet", system=s, backend="native", groups=groups)

    return [
        ("openmm-verlet", "OpenMM VerletIntegrator", 1, lambda s: (s, mm.VerletIntegrator(dt))),
        ("openmm-langevin", "OpenMM LangevinMiddleIntegrator", 1,
         lambda s: (s, mm.LangevinMiddleIntegrator(300 * unit.kelvin, 1 / unit.picosecond, dt))),
        ("verlet", "native verlet", 1, native()),
        ("verlet-nvt", "native verlet, thermostat (middle)", 1, native(temperature=300, random_seed=5)),
        ("verlet-nvt-ends", "native verlet, thermostat (ends)", 1,
         native(temperature=300, random_seed=5, thermostat_position="ends")),
        ("omelyan-2", "native omelyan-2", 2, native("omelyan-2")),
        ("verlet-mts", "native verlet, r-RESPA (PME reciprocal / 2)", 2, mts),
    ]


def measure(system, pos, vel, platform, precision, warmup, steps, calls=4, fusion=None, only=None) -> list:
    import openmm as mm

    from openmm_symprk.studies.platforms.speed import host_copies, intercept, intercept_counts, launches

    lib = intercept()
    out = []
    short = steps // calls
    for key, name, evals, make in integrators(system):
        if only and key not in only:
            continue
        s, ig = make(system)
        if fusion is not None and hasattr(ig, "setKernelFusion"):
            ig.setKernelFusion(fusion)
        ctx = mm.Context(s, ig, mm.Platform.getPlatformByName(platform), {"Precision": precision})
        ctx.setPositions(pos)
        ctx.setVelocities(vel)
        ig.step(warmup)
        native = hasattr(ig, "device_counts")
        row = {"key": key, "integrator": name, "force_evaluations": evals}
        for key, call_steps in (("one_call", [steps]), ("calls", [short] * calls)):
            lib.symprk_intercept_reset()
            own = ig.device_counts()[0] if native else 0
            for n in call_steps:
                ig.step(n)
            row[key] = intercept_counts(lib)
            if native:
                row[key]["own_launches"] = ig.device_counts()[0] - own
        one, split = row["one_call"], row["calls"]
        total = short * calls
        row["launches_per_step"] = launches(one) / steps
        row["copies_per_step"] = host_copies(one) / steps
        # (calls - 1) more calls over the same steps (total = steps when calls divides it)
        row["launches_per_call"] = (launches(split) - launches(one) * total / steps) / (calls - 1)
        row["copies_per_call"] = (host_copies(split) - host_copies(one) * total / steps) / (calls - 1)
        row["launches_per_step_beyond_calls"] = (launches(one) - row["launches_per_call"]) / steps
        row["copies_per_step_beyond_calls"] = (host_copies(one) - row["copies_per_call"]) / steps
        if native:
            row["own_launches_per_step"] = one["own_launches"] / steps
        out.append(row)
        del ctx
    return out


def table(rows, steps, calls) -> str:
    lines = [f"| integrator | force evaluations per step | launches per step | per force evaluation | host copies per "
             f"step | launches per call | copies per call | the plugin's own launches per step |", "|" + "---|" * 8]
    for r in rows:
        own = f"{r['own_launches_per_step']:.2f}" if "own_launches_per_step" in r else "-"
        lines.append(f"| {r['integrator']} | {r['force_evaluations']} | {r['launches_per_step']:.2f} | "
                     f"{r['launches_per_step'] / r['force_evaluations']:.2f} | {r['copies_per_step']:.2f} | "
                     f"{r['launches_per_call']:.1f} | {r['copies_per_call']:.1f} | {own} |")
    lines.append(f"\n(per step: of one step({steps}) call; per call: what {calls} calls of step({steps // calls}) add to "
                 f"the same steps, per call after the first)")
    return "\n".join(lines)


def kernels(rows, steps) -> str:
    lines = []
    for r in rows:
        per = r["one_call"]["per_kernel"]
        lines.append(f"{r['integrator']}: " + ", ".join(f"{k} {v / steps:g}" for k, v in sorted(per.items(), key=lambda kv: -kv[1])))
    return "\n".join(lines)


def build_parser():
    ap = argparse.ArgumentParser(prog="tools/count_launches.py", description=__doc__.split("\n\n")[0])
    ap.add_argument("--platform", default="OpenCL", help="OpenCL (default) or CUDA")
    ap.add_argument("--precision", default="mixed")
    ap.add_argument("--box-nm", type=float, default=2.2, help="edge of the TIP3P box (default 2.2 nm)")
    ap.add_argument("--warmup", type=int, default=10)
    ap.add_argument("--steps", type=int, default=100)
    ap.add_argument("--calls", type=int, default=4, help="the calls the steps are split into for the per-call cost")
    ap.add_argument("--fusion", type=int, default=None, choices=(0, 1, 2),
                    help="the native integrators' kernel fusion (SymPRKIntegrator.KernelFusion; default: theirs, 2)")
    ap.add_argument("--only", help="comma-separated rows to count (keys: openmm-verlet, openmm-langevin, verlet, "
                    "verlet-nvt, verlet-nvt-ends, omelyan-2, verlet-mts; default all)")
    ap.add_argument("--kernels", action="store_true", help="also each integrator's launches per step per kernel name")
    ap.add_argument("--json", metavar="FILE", help="write the rows as JSON to FILE")
    ap.add_argument("--build-dir", default=str(HERE.parent / "build" / "launch-intercept"),
                    help="where the intercept library is compiled")
    ap.add_argument("--exec", nargs=argparse.REMAINDER, metavar="COMMAND",
                    help="run COMMAND (the rest of the line) with the intercept preloaded instead")
    return ap


def main(argv=None) -> int:
    argv = list(sys.argv[1:] if argv is None else argv)
    args = build_parser().parse_args(argv)
    from openmm_symprk.studies.platforms.speed import intercept

    if args.exec or intercept() is None:
        lib = build(Path(args.build_dir))
        env = dict(os.environ)
        env["LD_PRELOAD"] = ":".join(p for p in (str(lib), env.get("LD_PRELOAD", "")) if p)
        command = args.exec if args.exec else [sys.executable, str(Path(__file__).resolve()), *argv]
        return subprocess.run(command, env=env).returncode
    import warnings

    import openmm as mm

    warnings.simplefilter("ignore")
    if args.steps % args.calls or args.calls < 2:
        raise SystemExit(f"--calls {args.calls} must be at least 2 and divide --steps {args.steps}")
    system, pos, vel = water_box(args.box_nm)
    only = set(args.only.split(",")) if args.only else None
    rows = measure(system, pos, vel, args.platform, args.precision, args.warmup, args.steps, args.calls, args.fusion, only)
    print(f"OpenMM {mm.version.full_version}, {args.platform} ({args.precision} precision), TIP3P box {args.box_nm} nm, "
          f"{system.getNumParticles()} atoms, PME, SETTLE; step({args.warmup}) first\n")
    print(table(rows, args.steps, args.calls))
    if args.kernels:
        print()
        print(kernels(rows, args.steps))
    if args.json:
        Path(args.json).write_text(json.dumps({"atoms": system.getNumParticles(), "steps": args.steps, "calls": args.calls,
                                                "platform": args.platform, "precision": args.precision, "rows": rows},
                                               indent=1))
    return 0


if __name__ == "__main__":
    sys.exit(main())
