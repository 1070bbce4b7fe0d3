"""``symprk bench``: work-precision sweeps and stability searches (``main(argv)``).

    symprk bench --quick                       # CI: seconds
    symprk bench --production                  # solvated villin, HMR, multiple time stepping: about two hours
    symprk bench --workers 2                   # the full sweep of docs/benchmarks.md
    symprk bench --resume                      # continue an interrupted sweep in the same --out
    symprk bench --retime --production         # time every finished run again on a quiet machine
    symprk bench --summary                     # print the tables of a finished sweep
    symprk bench --scenes water-rigid villin --methods verlet yoshida-4 --steps-fs 1 2
    symprk bench --system-xml system.xml --state state.xml     # your own system
    symprk bench --pdb protein.pdb --forcefield amber14-all.xml amber14/tip3pfb.xml
"""
from __future__ import annotations

import argparse
import json
import os

from ..core import platforms
from ..core.options import positive
from ...support.errors import InputError


def _list(values):
    """Accept both ``--x a b`` and ``--x a,b``."""
    if not values:
        return None
    out = []
    for v in values:
        out += [s for s in v.split(",") if s]
    return out


def _check_out(out: str):
    """The output folder must be a folder we can write (not a file, not read-only)."""
    if os.path.exists(out) and not os.path.isdir(out):
        raise InputError(f"--out {out} is a file; give a folder for the sweep's results")
    parent = out
    while parent and not os.path.exists(parent):
        parent = os.path.dirname(parent)
    if not os.access(parent or ".", os.W_OK):
        raise InputError(f"--out {out}: {os.path.abspath(parent or '.')} is not writable")


def build_parser(prog: str = "symprk bench") -> argparse.ArgumentParser:
    from ..core.scenes import SCENES

    p = argparse.ArgumentParser(
        prog=prog,
        description="Speed against accuracy: scenes x methods x step sizes from one shared initial state per "
                    "scene; energy, momentum, constraint and trajectory errors; force evaluations and wall time "
                    "per ps; largest stable step by bisection.  Writes results.json, summary.txt and charts.")
    p.add_argument("--quick", action="store_true", help="CI mode: tiny scenes, seconds")
    p.add_argument("--production", action="store_true",
                   help="production-shaped runs: solvated villin (with and without HMR) and an expensive-PME box, "
                        "NVE drift, fluctuation and ns/day (about two hours on 2 cores)")
    p.add_argument("--out", help="output folder (default bench-results/quick or bench-results/full)")
    p.add_argument("--scenes", nargs="+", metavar="NAME", help=f"scenes to run (of {', '.join(SCENES)})")
    p.add_argument("--methods", nargs="+", metavar="NAME",
                   help="rows: catalogue names (symprk methods) and/or openmm-verlet, openmm-langevin")
    p.add_argument("--steps-fs", nargs="+", metavar="H", help="step sizes (fs) for every selected scene")
    p.add_argument("--length-ps", type=positive(float), help="run length (ps) for every selected scene")
    p.add_argument("--no-stability", action="store_true", help="skip the stability searches")
    p.add_argument("--workers", type=int, default=2, help="local worker processes (<= 1: in this process)")
    p.add_argument("--scheduler", metavar="ADDRESS",
                   help="Dask distributed scheduler address (e.g. tcp://host:8786); needs the 'cluster' extra")
    p.add_argument("--resume", action="store_true", help="continue the sweep stored in --out")
    p.add_argument("--retime", action="store_true",
                   help="measure again the wall time of every finished run in --out (against OpenMM's "
                        "VerletIntegrator, in turns), keeping its accuracy figures; then continue as --resume")
    p.add_argument("--no-charts", action="store_true", help="skip the PNG charts")
    p.add_argument("--no-progress", action="store_true", help="no progress bar")
    p.add_argument("--summary", action="store_true", help="print the tables of the results in --out and exit")
    p.add_argument("--platform", help="OpenMM platform for every scene (default: Reference; CPU for the PME box)")
    p.add_argument("--threads", type=int, help="CPU platform threads per worker (default 1)")
    u = p.add_argument_group("your own system (added as scene 'user', or --name)")
    u.add_argument("--system-xml", metavar="FILE", help="serialized openmm.System")
    u.add_argument("--state", metavar="FILE", help="positions (and velocities): serialized State XML or PDB")
    u.add_argument("--pdb", metavar="FILE", help="PDB file (positions; with --forcefield also the topology)")
    u.add_argument("--forcefield", nargs="+", metavar="XML", help="force-field files for --pdb")
    u.add_argument("--name", default="user", help="scene name for your system")
    u.add_argument("--temperature", type=float, default=300.0, help="K, for velocities and the Langevin row")
    return p


def make_config(args) -> dict:
    from . import presets

    base = presets.quick() if args.quick else presets.production() if args.production else presets.full()
    scenes = _list(args.scenes)
    user = bool(args.system_xml or args.pdb)
    if user:
        entry = presets.user_defaults()
        entry["builder"] = "user"
        entry["params"] = {k: v for k, v in {"system_xml": args.system_xml, "state": args.state, "pdb": args.pdb,
                                              "forcefields": args.forcefield or (), "temperature": args.temperature,
                                              "platform": args.platform}.items() if v}
        if "forcefields" in entry["params"]:
            entry["params"]["forcefields"] = list(entry["params"]["forcefields"])
        base["scenes"][args.name] = entry
        if scenes is None:
            scenes = [args.name]
        elif args.name not in scenes:
            scenes.append(args.name)
    steps = None
    if args.steps_fs:
        try:
            steps = [float(h) for h in _list(args.steps_fs)]
        except ValueError:
            raise InputError(f"--steps-fs takes numbers of femtoseconds, got {' '.join(args.steps_fs)}") from None
        bad = [h for h in steps if not h > 0]
        if bad:
            raise InputError(f"--steps-fs must be positive, got {', '.join(f'{h:g}' for h in bad)}")
    if args.platform:
        platforms.check(args.platform)
    cfg = presets.select(base, scenes=scenes, methods=_list(args.methods), steps_fs=steps,
                         length_ps=args.length_ps, stability=not args.no_stability)
    if args.platform:
        for sc in cfg["scenes"].values():
            sc["platform"] = args.platform
    if args.threads:
        cfg["threads"] = args.threads
    return cfg


def run(args):
    from .aggregate import format_summary
    from .sweep import retime_sweep, run_sweep

    out = args.out or os.path.join("bench-results", "quick" if args.quick else
                                   "production" if args.production else "full")
    if args.summary:
        path = os.path.join(out, "results.json")
        if not os.path.exists(path):
            raise InputError(f"no results in {out} (run 'symprk bench --out {out}' first)")
        with open(path) as fh:
            print(format_summary(json.load(fh)))
        return
    _check_out(out)
    cfg = make_config(args)
    if args.retime:
        results = retime_sweep(cfg, out, workers=args.workers, charts=not args.no_charts,
                               progress=not args.no_progress)
    else:
        results = run_sweep(cfg, out, workers=args.workers, scheduler=args.scheduler, resume=args.resume,
                            charts=not args.no_charts, progress=not args.no_progress)
    print(format_summary(results))
    for path in results.get("charts", []):
        print(f"chart: {path}")
