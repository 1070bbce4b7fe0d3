"""``symprk drift``: energy drift over independent replicas, paired rows, a verdict at 3 SE.

    symprk drift hmr --quick                      # seconds: villin in vacuum stands in for the solvated box
    symprk drift hmr                              # 3 x 100 ps per row on solvated villin (hours; resumable)
    symprk drift exact-momentum --quick           # seconds
    symprk drift exact-momentum                   # 3 x 100 ps, CPU and OpenCL single/mixed/double, on and off
    symprk drift hmr --replicas 5                 # more replicas: the finished ones are reused
    symprk drift nvt --quick                      # NVT (total + heat-bath energy) next to NVE (= symprk nvt drift)
    symprk drift nvt --rows omelyan-2@4,nosehoover@2 --chart nvt.png

Finished runs are kept in --out and reused when the same command runs again (an interrupted study continues).
"""
from __future__ import annotations

import argparse
import os
import shutil
import sys

from ..core.options import add_study_arguments, run_study
from ..core.platforms import split
from . import presets
from ...support.errors import InputError


def build_parser(prog: str = "symprk drift"):
    ap = argparse.ArgumentParser(prog=prog, description=__doc__,
                                 formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("study", choices=presets.STUDIES,
                    help="hmr: our verlet vs OpenMM's VerletIntegrator at 4 fs with HMR (docs/production.md); "
                         "exact-momentum: drift with and without exact_momentum per precision (docs/conservation.md); "
                         "nvt: the thermostat's effective-energy drift next to NVE (docs/thermostat.md)")
    add_study_arguments(ap, quick="seconds: tiny runs, the pipeline end to end", default_workers=1,
                        out=None, out_help="drift-results/<study> or drift-results/<study>-quick",
                        workers="worker processes (default 1: runs use --threads each; 2 cores take one run at a time)",
                        length="NVE length per run (default 100 ps; --quick 0.2)", timing=False)
    ap.add_argument("--sample-ps", type=float, help="energy sampling interval (default 0.1 ps)")
    ap.add_argument("--constraint-tolerance", type=float, help="integrators' constraint tolerance (default 1e-5)")
    ap.add_argument("--threads", type=int, help="CPU platform threads per run (default 2; --quick 1)")
    ap.add_argument("--platforms", help="exact-momentum: comma-separated, e.g. CPU,OpenCL:mixed "
                                        f"(default {','.join(presets.PRECISION_PLATFORMS)})")
    ap.add_argument("--no-control", action="store_true", help="hmr: skip the 2 fs non-HMR control pair")
    ap.add_argument("--rows", metavar="METHOD@FS,...",
                    help="nvt: only these pairs, e.g. omelyan-2@4,nosehoover@2 (default: the full set)")
    ap.add_argument("--chart", help="nvt: also write the work-precision chart (PNG) here (always: <out>/nvt-drift.png)")
    ap.add_argument("--json", help="also write the summary as JSON to this file (always: <out>/results.json)")
    return ap


def _bad_platform(spec: str) -> bool:
    try:
        return split(spec)[0] not in ("CPU", "Reference", "OpenCL", "CUDA", "HIP")
    except ValueError:
        return True


def make_config(args) -> dict:
    if args.rows and args.study != "nvt":
        raise InputError("--rows applies to the nvt study only")
    if args.chart and args.study != "nvt":
        raise InputError("--chart applies to the nvt study only")
    if args.study in ("hmr", "nvt") and args.platforms:
        raise InputError("--platforms applies to the exact-momentum study only")
    if args.study == "nvt":
        cfg = presets.nvt(args.quick, [s.strip() for s in args.rows.split(",") if s.strip()] if args.rows else None)
    elif args.study == "hmr":
        cfg = presets.hmr(args.quick, control=not args.no_control)
    else:
        platforms = [p for p in (args.platforms or "").split(",") if p] or presets.PRECISION_PLATFORMS
        bad = [p for p in platforms if _bad_platform(p)]
        if bad:
            raise InputError(f"--platforms: {', '.join(bad)} not understood; give NAME or NAME:PRECISION, e.g. "
                             f"CPU,OpenCL:single,OpenCL:mixed,OpenCL:double")
        cfg = presets.exact_momentum(args.quick, platforms)
    for key in ("sample_ps", "constraint_tolerance", "threads"):
        if getattr(args, key) is not None:
            cfg[key] = getattr(args, key)
    if int(cfg["threads"]) < 1:
        raise InputError(f"--threads must be >= 1, got {cfg['threads']}")
    return cfg


def run(args):
    if not args.out:
        args.out = os.path.join("drift-results", args.study + ("-quick" if args.quick else ""))
    run_study(args, {}, lambda cfg: cfg.update(make_config(args)), "openmm_symprk.studies.drift.study",
              "openmm_symprk.studies.drift.report")
    for copy, name in ((args.json, "results.json"), (args.chart, "nvt-drift.png")):  # results.json is always written
        if copy and not os.path.exists(os.path.join(args.out, name)):
            print(f"{args.prog}: no chart was drawn (see above), so none is copied to {copy}", file=sys.stderr)
        elif copy:
            os.makedirs(os.path.dirname(os.path.abspath(copy)), exist_ok=True)
            shutil.copyfile(os.path.join(args.out, name), copy)
            print(f"wrote {copy}")
