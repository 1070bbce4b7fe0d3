"""``symprk fidelity``: what users compute from a trajectory (diffusion, reorientation, angular-velocity
correlation, structure, energies, equipartition), per integrator, step and thermostat, against Verlet at 0.5 fs
and against Verlet extrapolated to h -> 0."""
from __future__ import annotations

import argparse
import os
import sys

from . import presets


def build_parser():
    ap = argparse.ArgumentParser(prog="symprk fidelity", description=__doc__)
    ap.add_argument("--quick", action="store_true", help="64 waters, 0.6-ps runs, 2 replicas: seconds, large errors")
    ap.add_argument("--out", default="fidelity-results", help="output folder (finished runs are reused)")
    ap.add_argument("--workers", type=int, default=2, help="worker processes (each runs one run at a time)")
    ap.add_argument("--scheduler", metavar="ADDRESS",
                    help="Dask distributed scheduler address (e.g. tcp://host:8786) instead of local workers; "
                         "needs the 'cluster' extra")
    ap.add_argument("--rows", default=None,
                    help="comma-separated labels of the preset rows to run (the reference is always run), "
                         "e.g. 'verlet 2 fs,omelyan-2 4 fs'; default: all")
    ap.add_argument("--replicas", type=int, default=None)
    ap.add_argument("--length-ps", type=float, default=None, help="measured length per run (frames every sample_fs)")
    ap.add_argument("--no-timing", action="store_true", help="skip the wall-time measurement in turns")
    ap.add_argument("--no-progress", action="store_true")
    return ap


def select_rows(cfg: dict, text: str) -> list:
    """The reference row and the preset rows whose labels are named in ``text`` (comma-separated)."""
    from .rowspec import label

    wanted = [w.strip() for w in text.split(",") if w.strip()]
    labels = [label(r) for r in cfg["rows"]]
    unknown = [w for w in wanted if w not in labels]
    if unknown:
        raise ValueError(f"unknown row(s) {', '.join(repr(u) for u in unknown)}; the rows are: {'; '.join(labels)}")
    return [cfg["rows"][0]] + [r for r, lab in zip(cfg["rows"][1:], labels[1:]) if lab in wanted]


def main(argv=None) -> int:
    args = build_parser().parse_args(argv)
    cfg = presets.quick() if args.quick else presets.full()
    try:
        if args.rows:
            cfg["rows"] = select_rows(cfg, args.rows)
        if args.replicas is not None:
            cfg["replicas"] = args.replicas
        if args.length_ps is not None:
            cfg["length_ps"] = args.length_ps
        if args.workers < 1:
            raise ValueError(f"--workers must be >= 1, got {args.workers}")
        if os.path.isfile(args.out):
            raise ValueError(f"--out {args.out} is a file; give a folder")
        from .report import format_summary
        from .simulation import run_study

        summary = run_study(cfg, args.out, workers=args.workers, timing=not args.no_timing,
                            progress=not args.no_progress, scheduler=args.scheduler)
    except KeyboardInterrupt:
        print("symprk fidelity: interrupted (finished runs are kept; run again to continue)", file=sys.stderr)
        return 130
    except (ValueError, KeyError, OSError, RuntimeError, ImportError) as exc:
        print(f"symprk fidelity: error: {exc}", file=sys.stderr)
        return 2
    print(format_summary(summary))
    print(f"\nwrote {os.path.join(args.out, 'summary.txt')}, results.json and fidelity.png")
    return 0


if __name__ == "__main__":
    sys.exit(main())
