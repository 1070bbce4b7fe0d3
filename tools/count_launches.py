#!/usr/bin/env python3
"""Count what a step asks of the device: kernel launches and host transfers per step of OpenMM's VerletIntegrator and
LangevinMiddleIntegrator and of the native integrator's plan shapes, each on the same Context set-up.

    python tools/count_launches.py                  # a 2.2 nm TIP3P box, PME, HBonds, OpenCL mixed: the table
    python tools/count_launches.py --kernels        # and each integrator's launches per kernel name
    python tools/count_launches.py --json out.json  # the numbers as JSON (tests/plugin/test_launch_counts.py)

It compiles tools/launch_intercept.cpp with g++ (into build/launch-intercept/, or --build-dir) and runs itself again
with that library preloaded (LD_PRELOAD): every clEnqueueNDRangeKernel, device-side copy and fill counts as a launch,
every clEnqueueReadBuffer, WriteBuffer and MapBuffer as a host copy (on CUDA: cuLaunchKernel, cuMemcpy*).  For each
integrator: a Context, ``step(warmup)``, then the counts of one ``step(steps)`` call per step (the issue's measure),
and of one ``step(steps // 2)`` call, whose difference gives the cost of a step apart from the cost of a call.  The
native rows also show the plugin's own launches per step (``getKernelLaunches``: its kernels alone).
"""
from __future__ import annotations

import argparse
import ctypes
import json
import os
import subprocess
import sys
from pathlib import Path

HERE = Path(__file__).resolve().parent
SOURCE = HERE / "launch_intercept.cpp"
#: the intercept's counters, in the order of symprk_intercept_count
COUNTERS = ("kernels", "device_copies", "fills", "reads", "writes", "maps")


def build(out_dir: Path) -> Path:
    """Compile the intercept library into out_dir (again only when the source is newer); its path."""
    out_dir.mkdir(parents=True, exist_ok=True)
    lib = out_dir / "launch_intercept.so"
    if not lib.exists() or lib.stat().st_mtime < SOURCE.stat().st_mtime:
        subprocess.run([os.environ.get("CXX", "g++"), "-O2", "-shared", "-fPIC", "-o", str(lib), str(SOURCE), "-ldl"],
                       check=True)
    return lib


def intercept():
    """The preloaded intercept library, or None when this process runs without it."""
    try:
        lib = ctypes.CDLL(None)
        lib.symprk_intercept_count.restype = ctypes.c_longlong
        return lib
    except AttributeError:
        return None


def snapshot(lib) -> dict:
    counts = {name: int(lib.symprk_intercept_count(i)) for i, name in enumerate(COUNTERS)}
    size = lib.symprk_intercept_kernels(None, 0)
    buf = ctypes.create_string_buffer(size)
    lib.symprk_intercept_kernels(buf, size)
    counts["per_kernel"] = {line.rsplit(" ", 1)[0]: int(line.rsplit(" ", 1)[1])
                            for line in buf.value.decode().splitlines() if line}
    return counts


def launches(c: dict) -> int:
    return c["kernels"] + c["device_copies"] + c["fills"]


def copies(c: dict) -> int:
    return c["reads"] + c["writes"] + c["maps"]


def water_box(box_nm: float):
    """(System, positions, velocities): the rigid TIP3P box of ``symprk speed`` (PME, 1 nm cutoff, SETTLE; no
    CMMotionRemover), minimised, velocities at 300 K."""
    from openmm_symprk.studies.platforms.speed import water_box_system

    _, system, pos, vel = water_box_system(box_nm)
    return system, pos, vel


def integrators(system):
    """[(name, force evaluations per step, factory(system) -> (system, integrator))]."""
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
        ("OpenMM VerletIntegrator", 1, lambda s: (s, mm.VerletIntegrator(dt))),
        ("OpenMM LangevinMiddleIntegrator", 1,
         lambda s: (s, mm.LangevinMiddleIntegrator(300 * unit.kelvin, 1 / unit.picosecond, dt))),
        ("native verlet", 1, native()),
        ("native verlet, thermostat (middle)", 1, native(temperature=300, random_seed=5)),
        ("native verlet, thermostat (ends)", 1, native(temperature=300, random_seed=5, thermostat_position="ends")),
        ("native omelyan-2", 2, native("omelyan-2")),
        ("native verlet, r-RESPA (PME reciprocal / 2)", 2, mts),
    ]


def measure(system, pos, vel, platform, precision, warmup, steps, fusion=None) -> list:
    import openmm as mm

    lib = intercept()
    out = []
    for name, evals, make in integrators(system):
        s, ig = make(system)
        if fusion is not None and hasattr(ig, "setKernelFusion"):
            ig.setKernelFusion(fusion)
        ctx = mm.Context(s, ig, mm.Platform.getPlatformByName(platform), {"Precision": precision})
        ctx.setPositions(pos)
        ctx.setVelocities(vel)
        ig.step(warmup)
        native = hasattr(ig, "getKernelLaunches")
        row = {"integrator": name, "force_evaluations": evals}
        for n, key in ((steps, "long"), (steps // 2, "short")):
            lib.symprk_intercept_reset()
            own = ig.getKernelLaunches() if native else 0
            ig.step(n)
            row[key] = snapshot(lib)
            if native:
                row[key]["own_launches"] = int(ig.getKernelLaunches()) - own
        long, short = row["long"], row["short"]
        half = steps - steps // 2
        row["launches_per_step"] = launches(long) / steps
        row["copies_per_step"] = copies(long) / steps
        row["marginal_launches_per_step"] = (launches(long) - launches(short)) / half
        row["marginal_copies_per_step"] = (copies(long) - copies(short)) / half
        row["launches_per_call"] = launches(long) - steps * row["marginal_launches_per_step"]
        row["copies_per_call"] = copies(long) - steps * row["marginal_copies_per_step"]
        if native:
            row["own_launches_per_step"] = long["own_launches"] / steps
        out.append(row)
        del ctx
    return out


def table(rows, steps) -> str:
    head = (f"| integrator | force evaluations per step | launches per step (one step({steps}) call) | per force "
            f"evaluation | host copies per step | launches per step beyond a call's | per call | copies per step "
            f"beyond a call's | per call | the plugin's own launches per step |")
    lines = [head, "|" + "---|" * 10]
    for r in rows:
        own = f"{r['own_launches_per_step']:.2f}" if "own_launches_per_step" in r else "-"
        lines.append(f"| {r['integrator']} | {r['force_evaluations']} | {r['launches_per_step']:.2f} | "
                     f"{r['launches_per_step'] / r['force_evaluations']:.2f} | {r['copies_per_step']:.2f} | "
                     f"{r['marginal_launches_per_step']:.2f} | {r['launches_per_call']:.0f} | "
                     f"{r['marginal_copies_per_step']:.2f} | {r['copies_per_call']:.0f} | {own} |")
    return "\n".join(lines)


def kernels(rows, steps) -> str:
    lines = []
    for r in rows:
        per = r["long"]["per_kernel"]
        lines.append(f"{r['integrator']}: " + ", ".join(f"{k} {v / steps:g}" for k, v in sorted(per.items(), key=lambda kv: -kv[1])))
    return "\n".join(lines)


def build_parser():
    ap = argparse.ArgumentParser(prog="tools/count_launches.py", description=__doc__.split("\n\n")[0])
    ap.add_argument("--platform", default="OpenCL", help="OpenCL (default) or CUDA")
    ap.add_argument("--precision", default="mixed")
    ap.add_argument("--box-nm", type=float, default=2.2, help="edge of the TIP3P box (default 2.2 nm)")
    ap.add_argument("--warmup", type=int, default=10)
    ap.add_argument("--steps", type=int, default=100)
    ap.add_argument("--fusion", type=int, default=None, choices=(0, 1, 2),
                    help="the native integrators' kernel fusion (SymPRKIntegrator.KernelFusion; default: theirs, 2)")
    ap.add_argument("--kernels", action="store_true", help="also each integrator's launches per step per kernel name")
    ap.add_argument("--json", metavar="FILE", help="write the rows as JSON to FILE")
    ap.add_argument("--build-dir", default=str(HERE.parent / "build" / "launch-intercept"),
                    help="where the intercept library is compiled")
    return ap


def main(argv=None) -> int:
    args = build_parser().parse_args(argv)
    if intercept() is None:
        lib = build(Path(args.build_dir))
        env = dict(os.environ)
        env["LD_PRELOAD"] = ":".join(p for p in (str(lib), env.get("LD_PRELOAD", "")) if p)
        return subprocess.run([sys.executable, str(Path(__file__).resolve()), *(argv if argv is not None else sys.argv[1:])],
                              env=env).returncode
    import warnings

    import openmm as mm

    warnings.simplefilter("ignore")
    system, pos, vel = water_box(args.box_nm)
    rows = measure(system, pos, vel, args.platform, args.precision, args.warmup, args.steps, args.fusion)
    print(f"OpenMM {mm.version.full_version}, {args.platform} ({args.precision} precision), TIP3P box {args.box_nm} nm, "
          f"{system.getNumParticles()} atoms, PME, SETTLE; step({args.warmup}), then one step({args.steps}) call and "
          f"one step({args.steps // 2}) call\n")
    print(table(rows, args.steps))
    if args.kernels:
        print()
        print(kernels(rows, args.steps))
    if args.json:
        Path(args.json).write_text(json.dumps({"atoms": system.getNumParticles(), "steps": args.steps,
                                                "platform": args.platform, "precision": args.precision, "rows": rows},
                                               indent=1))
    return 0


if __name__ == "__main__":
    sys.exit(main())
