"""``symprk equipartition``: rigid water's T_rot - T_trans per method and step, against Verlet at 0.5 fs."""
from __future__ import annotations

import argparse
import os
import sys

from . import presets


def _rows(text: str) -> list:
    """'verlet:0.5,omelyan-2:4' -> [['verlet', 0.5], ['omelyan-2', 4.0]]."""
    rows = []
    for item in text.split(","):
        item = item.strip()
        if not item:
            continue
        method, sep, h = item.rpartition(":")
        try:
            rows.append([method, float(h)])
        except ValueError:
            raise argparse.ArgumentTypeError(f"{item!r} is not METHOD:STEP_FS (e.g. verlet:0.5)") from None
        if not sep or not method:
            raise argparse.ArgumentTypeError(f"{item!r} is not METHOD:STEP_FS (e.g. verlet:0.5)")
    return rows


def build_parser():
    ap = argparse.ArgumentParser(prog="symprk equipartition", description=__doc__)
    ap.add_argument("--quick", action="store_true", help="64 waters, short runs: seconds, large error bars")
    ap.add_argument("--out", default="equipartition-results", help="output folder (finished runs are reused)")
    ap.add_argument("--workers", type=int, default=2, help="worker processes (each runs one NVE run at a time)")
    ap.add_argument("--scheduler", metavar="ADDRESS",
                    help="Dask distributed scheduler address (e.g. tcp://host:8786) instead of local workers; "
                         "needs the 'cluster' extra")
    ap.add_argument("--models", default=None, help="comma-separated water models (spce, tip3p); default: all (--quick: spce)")
    ap.add_argument("--rows", type=_rows, default=None,
                    help="METHOD:STEP_FS,... for every model (rigid:METHOD for the rigid-body engine); "
                         "the reference verlet:0.5 is added")
    ap.add_argument("--replicas", type=int, default=None)
    ap.add_argument("--length-ps", type=float, default=None, help="NVE length measured per replica")
    ap.add_argument("--no-timing", action="store_true", help="skip the wall-time measurement in turns")
    ap.add_argument("--no-progress", action="store_true")
    return ap


def main(argv=None) -> int:
    args = build_parser().parse_args(argv)
    cfg = presets.quick() if args.quick else presets.full()
    try:
        if args.models:
            wanted = [m.strip() for m in args.models.split(",") if m.strip()]
            unknown = [m for m in wanted if m not in presets.full()["models"]]
            if unknown:
                raise ValueError(f"unknown water model(s) {', '.join(unknown)}; known: "
                                 f"{', '.join(presets.full()['models'])}")
            base = presets.full()["models"]
            cfg["models"] = {m: cfg["models"].get(m, base[m]) for m in wanted}
        if args.rows:
            ref = [cfg["reference"][0], float(cfg["reference"][1])]
            rows = ([ref] if ref not in args.rows else []) + args.rows
            cfg["models"] = {m: rows for m in cfg["models"]}
        if args.replicas is not None:
            cfg["replicas"] = args.replicas
        if args.length_ps is not None:
            cfg["length_ps"] = args.length_ps
        if args.workers < 1:
            raise ValueError(f"--workers must be >= 1, got {args.workers}")
        if os.path.isfile(args.out):
            raise ValueError(f"--out {args.out} is a file; give a folder")
        from .report import format_summary
        from .study import run_study

        summary = run_study(cfg, args.out, workers=args.workers, timing=not args.no_timing,
                            progress=not args.no_progress, scheduler=args.scheduler)
    except KeyboardInterrupt:
        print("symprk equipartition: interrupted (finished runs are kept; run again to continue)", file=sys.stderr)
        return 130
    except (ValueError, KeyError, OSError, RuntimeError, ImportError) as exc:
        print(f"symprk equipartition: error: {exc}", file=sys.stderr)
        return 2
    print(format_summary(summary))
    print(f"\nwrote {os.path.join(args.out, 'summary.txt')}, results.json and equipartition.png")
    return 0


if __name__ == "__main__":
    sys.exit(main())
