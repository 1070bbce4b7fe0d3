"""``symprk nvt cost`` and ``symprk nvt drift``: the thermostat's measurements (docs/thermostat.md).

    symprk nvt cost [--quick] [--scenes water,villin] [--threads 2] [--no-forces] [--platform OpenCL]  # time per step vs LangevinMiddle
    symprk nvt drift [--quick] [--replicas 3] [--length-ps 20] [--rows omelyan-2@4,...] [--chart PNG]  # = symprk drift nvt
    symprk nvt known [--quick] [--platforms Reference,CPU,OpenCL] [--json FILE]  # the random numbers' known answers

``--quick`` runs in seconds (small box, few steps: a check of the pipeline, not a measurement).
"""
from __future__ import annotations

import argparse

from ...support.files import write_json
from ..core.options import positive


def _scenes(text):
    names = [s.strip() for s in text.split(",") if s.strip()]
    bad = [s for s in names if s not in ("water", "villin")]
    if bad or not names:
        raise argparse.ArgumentTypeError(f"unknown scene(s) {', '.join(bad) or repr(text)}; known: water, villin")
    return names


def build_parser(prog: str = "symprk nvt"):
    p = argparse.ArgumentParser(prog=prog, description="measurements of the NVT thermostat")
    sub = p.add_subparsers(dest="what", required=True)
    c = sub.add_parser("cost", help="time per step against OpenMM's LangevinMiddleIntegrator (CPU platform)")
    c.add_argument("--quick", action="store_true", help="small water box, few steps (seconds)")
    c.add_argument("--scenes", type=_scenes, default=None, help="water,villin (default both; --quick: water)")
    c.add_argument("--steps", type=positive(int), default=None, help="steps per timed block")
    c.add_argument("--rounds", type=positive(int), default=None, help="rounds of blocks (each row keeps its fastest)")
    c.add_argument("--threads", type=positive(int), default=2, help="CPU platform threads (default 2)")
    c.add_argument("--platform", default="CPU", help="OpenMM platform: CPU (default) or OpenCL, CUDA, Reference")
    c.add_argument("--no-forces", action="store_true",
                   help="remove every force (constraints stay): time the integrators' own work, the thermostat's cost")
    c.add_argument("--json", default=None, help="also write the tables as JSON to this file")
    k = sub.add_parser("known", help="known answers: the moments of each event's random numbers, and the stationary "
                                     "temperatures of harmonic oscillators, per backend and platform")
    k.add_argument("--quick", action="store_true", help="fewer draws and steps (a minute; resolves 0.2 %%, not 0.05 %%)")
    k.add_argument("--platforms", default="Reference,CPU,OpenCL", help="comma-separated (default Reference,CPU,OpenCL)")
    k.add_argument("--json", default=None, help="also write the tables as JSON to this file")
    sub.add_parser("drift", add_help=False, help="effective-energy drift (kT/ns/DOF), NVT next to NVE, and its chart: "
                                                 "symprk drift nvt (its options: symprk nvt drift --help)")
    return p


def run(args):
    return _known(args) if args.what == "known" else _cost(args)


def _known(args):
    from .known import run

    tables = run(quick=args.quick, platforms=[p.strip() for p in args.platforms.split(",") if p.strip()])
    if args.json:
        write_json(args.json, tables)


def _cost(args):
    from .cost import run

    scenes = args.scenes or (["water"] if args.quick else ["water", "villin"])
    tables = run(scenes, quick=args.quick, steps=args.steps, rounds=args.rounds, threads=args.threads,
                 no_forces=args.no_forces, platform=args.platform)
    if args.json:
        write_json(args.json, tables)
        print(f"wrote {args.json}")
