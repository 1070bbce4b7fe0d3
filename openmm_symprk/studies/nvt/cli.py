"""``symprk nvt cost`` and ``symprk nvt drift``: the thermostat's measurements (docs/thermostat.md).

    symprk nvt cost [--quick] [--scenes water,villin] [--threads 2] [--no-forces]  # time per step vs LangevinMiddle
    symprk nvt drift [--quick] [--replicas 3] [--length-ps 20] [--rows omelyan-2@4,...] [--chart PNG]

``--quick`` runs in seconds (small box, few steps: a check of the pipeline, not a measurement).
"""
from __future__ import annotations

import argparse

from ...support.files import write_json
from ..core.cli import positive


def _scenes(text):
    names = [s.strip() for s in text.split(",") if s.strip()]
    bad = [s for s in names if s not in ("water", "villin")]
    if bad or not names:
        raise argparse.ArgumentTypeError(f"unknown scene(s) {', '.join(bad) or repr(text)}; known: water, villin")
    return names


def build_parser():
    p = argparse.ArgumentParser(prog="symprk nvt", description="measurements of the NVT thermostat")
    sub = p.add_subparsers(dest="what", required=True)
    c = sub.add_parser("cost", help="time per step against OpenMM's LangevinMiddleIntegrator (CPU platform)")
    c.add_argument("--quick", action="store_true", help="small water box, few steps (seconds)")
    c.add_argument("--scenes", type=_scenes, default=None, help="water,villin (default both; --quick: water)")
    c.add_argument("--steps", type=positive(int), default=None, help="steps per timed block")
    c.add_argument("--rounds", type=positive(int), default=None, help="rounds of blocks (each row keeps its fastest)")
    c.add_argument("--threads", type=positive(int), default=2, help="CPU platform threads (default 2)")
    c.add_argument("--no-forces", action="store_true",
                   help="remove every force (constraints stay): time the integrators' own work, the thermostat's cost")
    c.add_argument("--json", default=None, help="also write the tables as JSON to this file")
    d = sub.add_parser("drift", help="effective-energy drift (kT/ns/DOF), NVT next to NVE, and its chart")
    d.add_argument("--quick", action="store_true", help="two rows, 0.2-ps runs, one replica (seconds)")
    d.add_argument("--replicas", type=positive(int), default=None, help="independent replicas (default 3)")
    d.add_argument("--length-ps", type=positive(float), default=None, help="length of each run (default 20 ps)")
    d.add_argument("--threads", type=positive(int), default=2, help="CPU platform threads (default 2)")
    d.add_argument("--rows", default=None, metavar="METHOD@FS,...",
                   help="only these rows, e.g. omelyan-2@4,nosehoover@2 (default: the full set)")
    d.add_argument("--chart", default=None, help="write the work-precision chart (PNG) here")
    d.add_argument("--json", default=None, help="also write the table as JSON to this file")
    return p


def _write_json(path, data):
    write_json(path, data)
    print(f"wrote {path}")


def main(argv=None) -> int:
    args = build_parser().parse_args(argv)
    if args.what == "cost":
        from .cost import run

        scenes = args.scenes or (["water"] if args.quick else ["water", "villin"])
        tables = run(scenes, quick=args.quick, steps=args.steps, rounds=args.rounds, threads=args.threads,
                     no_forces=args.no_forces)
        if args.json:
            _write_json(args.json, tables)
        return 0
    from .drift import run

    from .drift import pairs_from

    try:
        pairs = pairs_from(args.rows) if args.rows else None
    except Exception as exc:  # a bad row: one line, exit status 2
        build_parser().error(str(exc))
    result = run(quick=args.quick, replicas=args.replicas, length_ps=args.length_ps, threads=args.threads,
                 pairs=pairs)
    if args.chart:
        from .chart import work_precision

        print(f"wrote {work_precision(result, args.chart)}")
    if args.json:
        _write_json(args.json, result)
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
