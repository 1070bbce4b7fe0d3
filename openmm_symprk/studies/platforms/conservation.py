"""Conservation study: platform x method x exact-momentum projection, as a markdown table.

    symprk conservation            # full table (a few minutes)
    symprk conservation --quick    # 8 waters, 500 steps, verlet

For every scene, platform and method, two integrators run side by side from the same state: the
method as compiled without projection ("off") and the complete exact-momentum program ("on":
``SymplecticIntegrator(..., exact_momentum=True, system=...)``, i.e. projected kicks, exact masses and the
restoration of constraint impulses).  The run is split in chunks that alternate between the two
Contexts, so both see the same machine load; the cost ratio is the ratio of the fastest chunk of each
(ms per step).  |dL|/|L| is about the centre of mass, |dP| in amu nm/ps, both in float64 from the
State after ``--steps`` steps (after one warm-up step).  A second table shows the failure cases on
Reference: a non-symplectic method (rk4), a thermostat (LangevinMiddleIntegrator) and a
CMMotionRemover (L about the origin).
"""
from __future__ import annotations

import argparse
import sys
import warnings

import numpy as np
import openmm as mm

from ...conservation.diagnostics import angular_momentum, linear_momentum
from ...support.files import write_text
from ..core import platforms
from ..core.engine import RowEngine
from ..core.rows import Row
from ..core.timing import time_rows
from ...support.errors import InputError

DEFAULT_PLATFORMS = ("Reference", "CPU", "OpenCL:single", "OpenCL:mixed", "OpenCL:double")
DEFAULT_METHODS = ("verlet", "yoshida-4")
DEFAULT_SCENES = ("water", "protein")


def _scene(name, n_waters):
    from ...systems import scenes

    builders = {"water": lambda: scenes.water_cluster(n_waters), "protein": scenes.protein_vacuum,
                "flexible-water": lambda: scenes.water_cluster(n_waters, rigid=False)}
    if name not in builders:
        raise InputError(f"unknown scene {name!r} (water, protein, flexible-water)")
    return builders[name]()


def _momenta(ctx):
    return angular_momentum(ctx), linear_momentum(ctx)


def compare(scene, spec, method, steps, step_size=0.002, chunk=None, backend="auto"):
    """Run off and on side by side (``steps`` rounded down to whole chunks); return a dict of figures."""
    if platforms.split(spec)[0] == "OpenCL" and scene.n_atoms < 2:
        raise InputError("PoCL crashes on 1-particle systems")
    row = Row(method, step_size * 1e3, backend=backend)
    engines = {k: RowEngine(r, scene, platform=spec, threads=None, quiet=False)
               for k, r in (("off", row), ("on", row.replace(exact_momentum=True)))}
    start = {}
    for k, eng in engines.items():
        eng.step(1)  # warm-up: kernels compiled, forces cached
        start[k] = _momenta(eng.context)
    chunk = chunk or max(1, min(100, steps // 10))
    timings = time_rows(engines, chunk, rounds=max(1, steps // chunk))
    out = {"scene": scene.name, "atoms": scene.n_atoms, "platform": spec, "method": method, "steps": steps,
           "backend": engines["off"].integrator.backend}
    for k, eng in engines.items():
        (L1, P1), (L0, P0) = _momenta(eng.context), start[k]
        out[f"dL_{k}"] = float(np.linalg.norm(L1 - L0) / np.linalg.norm(L0))
        out[f"dP_{k}"] = float(np.linalg.norm(P1 - P0))
        out[f"ms_{k}"] = timings[k].best * 1e3
    out["ratio"] = out["ms_on"] / out["ms_off"]
    return out


def failure_cases(steps=500):
    """Reference-platform runs where momentum is not conserved, for the second table."""
    from ...systems import scenes

    rows = []
    morse = scenes.morse_molecule()
    water = scenes.water_cluster(8)

    def drift(scene, label, about="com", system=None, velocities=None):
        eng = RowEngine(Row.parse(label), system or scene.system, scene.positions,
                        scene.velocities if velocities is None else velocities, platform="Reference", start=False,
                        quiet=False)
        L0, P0 = angular_momentum(eng.context, about=about), linear_momentum(eng.context)
        eng.step(steps)
        L1, P1 = angular_momentum(eng.context, about=about), linear_momentum(eng.context)
        return float(np.linalg.norm(L1 - L0) / np.linalg.norm(L0)), float(np.linalg.norm(P1 - P0))

    for em in ("", " exact-momentum"):
        rows.append(("rk4 (not symplectic), Morse molecule" + (", projected" if em else ""), "com",
                     *drift(morse, f"rk4 1 fs{em}"), "method error: projection cannot help"))
    rows.append(("verlet, Morse molecule (reference)", "com", *drift(morse, "verlet 1 fs"), "round-off"))
    rows.append(("LangevinMiddleIntegrator, 8 waters", "com", *drift(water, "langevin 2 fs friction 1/ps T 150 K"),
                 "thermostat"))
    system = mm.XmlSerializer.clone(water.system)
    system.addForce(mm.CMMotionRemover(1))
    v = water.velocities + np.array([0.3, -0.2, 0.1])
    for about in ("com", "origin"):
        rows.append(("verlet + CMMotionRemover, 8 waters drifting", about,
                     *drift(water, "verlet 2 fs", about=about, system=system, velocities=v),
                     "L about the centre of mass kept" if about == "com" else "L about the origin changes"))
    return rows


def _fmt(x):
    return f"{x:.1e}"


def table(rows) -> str:
    head = ("| scene | platform | method | backend | abs(dL)/abs(L) off | abs(dL)/abs(L) on | abs(dP) off | abs(dP) on "
            "| ms/step off | ms/step on | cost on/off |")
    lines = [head, "|" + "---|" * 11]
    for r in rows:
        lines.append(f"| {r['scene']} ({r['atoms']} atoms) | {r['platform']} | {r['method']} | {r['backend']} | "
                     f"{_fmt(r['dL_off'])} | "
                     f"{_fmt(r['dL_on'])} | {_fmt(r['dP_off'])} | {_fmt(r['dP_on'])} | {r['ms_off']:.3f} | "
                     f"{r['ms_on']:.3f} | {r['ratio']:.2f} |")
    return "\n".join(lines)


def failure_table(rows) -> str:
    lines = ["| case | L about | abs(dL)/abs(L) | abs(dP) | why |", "|---|---|---|---|---|"]
    for case, about, dl, dp, why in rows:
        lines.append(f"| {case} | {about} | {_fmt(dl)} | {_fmt(dp)} | {why} |")
    return "\n".join(lines)


def build_parser(prog: str = "symprk conservation"):
    p = argparse.ArgumentParser(prog=prog, description=__doc__.split("\n\n")[0],
                                formatter_class=argparse.RawDescriptionHelpFormatter)
    p.add_argument("--steps", type=int, default=2000, help="steps per run (default 2000)")
    p.add_argument("--platforms", default=",".join(DEFAULT_PLATFORMS),
                   help="comma-separated, e.g. Reference,CPU,OpenCL:mixed (default: all five)")
    p.add_argument("--methods", default=",".join(DEFAULT_METHODS), help="catalogue methods (default verlet,yoshida-4)")
    p.add_argument("--scenes", default=",".join(DEFAULT_SCENES), help="water, protein, flexible-water")
    p.add_argument("--waters", type=int, default=27, help="waters in the cluster scenes (default 27)")
    p.add_argument("--step-size", type=float, default=0.002, help="ps (default 0.002)")
    p.add_argument("--backend", default="auto", choices=("auto", "native", "custom"),
                   help="integrator backend (default auto: the native plugin where it serves every platform)")
    p.add_argument("--no-failures", action="store_true", help="skip the failure-case table")
    p.add_argument("--quick", action="store_true",
                   help="8 waters, 500 steps, verlet, no protein: a smoke run of under a minute")
    p.add_argument("--out", help="also write the markdown to this file")
    return p


def run(args):
    if args.quick:
        args.steps, args.waters, args.methods, args.scenes = 500, 8, "verlet", "water"
    warnings.simplefilter("ignore")  # conservation warnings are the subject here, not news
    specs = [s for s in args.platforms.split(",") if s]
    missing = [s for s in specs if not platforms.available(s)]
    specs = [s for s in specs if s not in missing]
    rows = []
    for scene_name in args.scenes.split(","):
        scene = _scene(scene_name, args.waters)
        for spec in specs:
            for method in args.methods.split(","):
                r = compare(scene, spec, method, args.steps, args.step_size, backend=args.backend)
                rows.append(r)
                print(f"  {scene.name} {spec} {method}: dL/L off {_fmt(r['dL_off'])} on {_fmt(r['dL_on'])}, "
                      f"cost x{r['ratio']:.2f}", file=sys.stderr, flush=True)
    parts = [f"Command: `{' '.join([args.prog, *args.argv])}` ({args.steps} steps of {args.step_size * 1000:g} fs; OpenMM "
             f"{mm.Platform.getOpenMMVersion()})", "", table(rows)]
    if missing:
        parts += ["", f"Platforms not available here: {', '.join(missing)}"]
    if not args.no_failures:
        parts += ["", "Failure cases (Reference, 500 steps):", "", failure_table(failure_cases())]
    text = "\n".join(parts)
    print(text)
    if args.out:
        write_text(args.out, text + "\n")
