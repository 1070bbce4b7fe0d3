"""``symprk drift``: NVE energy drift over independent replicas, paired rows, a verdict at 3 SE.

    symprk drift hmr --quick                      # seconds: villin in vacuum stands in for the solvated box
    symprk drift hmr                              # 3 x 100 ps per row on solvated villin (hours; resumable)
    symprk drift exact-momentum --quick           # seconds
    symprk drift exact-momentum                   # 3 x 100 ps, CPU and OpenCL single/mixed/double, on and off
    symprk drift hmr --replicas 5                 # more replicas: the finished ones are reused

Finished runs are kept in --out and reused when the same command runs again (an interrupted study continues).
"""
from __future__ import annotations

import argparse
import os
import sys

from ..core.cli import run_study_command
from . import presets


def build_parser():
    ap = argparse.ArgumentParser(prog="symprk drift", description=__doc__,
                                 formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("study", choices=("hmr", "exact-momentum"),
                    help="hmr: our verlet vs OpenMM's VerletIntegrator at 4 fs with HMR (docs/production.md); "
                         "exact-momentum: drift with and without exact_momentum per precision (docs/conservation.md)")
    ap.add_argument("--quick", action="store_true", help="seconds: tiny runs, the pipeline end to end")
    ap.add_argument("--out", help="output folder (default drift-results/<study>[-quick]); finished runs are reused")
    ap.add_argument("--replicas", type=int, help="independent replicas per row (default 3)")
    ap.add_argument("--length-ps", type=float, help="NVE length per run (default 100 ps; --quick 0.2)")
    ap.add_argument("--sample-ps", type=float, help="energy sampling interval (default 0.1 ps)")
    ap.add_argument("--constraint-tolerance", type=float, help="integrators' constraint tolerance (default 1e-5)")
    ap.add_argument("--threads", type=int, help="CPU platform threads per run (default 2; --quick 1)")
    ap.add_argument("--platforms", help="exact-momentum: comma-separated, e.g. CPU,OpenCL:mixed "
                                        f"(default {','.join(presets.PRECISION_PLATFORMS)})")
    ap.add_argument("--no-control", action="store_true", help="hmr: skip the 2 fs non-HMR control pair")
    ap.add_argument("--workers", type=int, default=1,
                    help="worker processes (default 1: runs use --threads each; 2 cores take one run at a time)")
    ap.add_argument("--scheduler", metavar="ADDRESS", help="Dask scheduler address instead of local workers")
    ap.add_argument("--no-progress", action="store_true")
    ap.add_argument("--report-only", action="store_true",
                    help="run nothing: summarise the finished runs in --out (unfinished ones are left out)")
    return ap


def make_config(args) -> dict:
    if args.study == "hmr":
        if args.platforms:
            raise ValueError("--platforms applies to the exact-momentum study only")
        cfg = presets.hmr(args.quick, control=not args.no_control)
    else:
        platforms = [p for p in (args.platforms or "").split(",") if p] or presets.PRECISION_PLATFORMS
        bad = [p for p in platforms if p.partition(":")[0] not in ("CPU", "Reference", "OpenCL", "CUDA", "HIP")
               or p.partition(":")[2] not in ("", "single", "mixed", "double")]
        if bad:
            raise ValueError(f"--platforms: {', '.join(bad)} not understood; give NAME or NAME:PRECISION, e.g. "
                             f"CPU,OpenCL:single,OpenCL:mixed,OpenCL:double")
        cfg = presets.exact_momentum(args.quick, platforms)
    for key in ("sample_ps", "constraint_tolerance", "threads"):
        if getattr(args, key) is not None:
            cfg[key] = getattr(args, key)
    if int(cfg["threads"]) < 1:
        raise ValueError(f"--threads must be >= 1, got {cfg['threads']}")
    return cfg


def main(argv=None) -> int:
    args = build_parser().parse_args(argv)
    if not args.out:
        args.out = os.path.join("drift-results", args.study + ("-quick" if args.quick else ""))
    return run_study_command("symprk drift", args, {}, lambda cfg: cfg.update(make_config(args)),
                             "openmm_symprk.studies.drift.study", "openmm_symprk.studies.drift.report")


if __name__ == "__main__":
    sys.exit(main())
