"""``symprk equipartition``: rigid water's T_rot - T_trans per method and step, against Verlet at 0.5 fs."""
from __future__ import annotations

import argparse

from ..core.options import add_study_arguments, run_study
from ..core.rows import Row
from . import presets
from ...support.errors import InputError


def _rows(text: str) -> list:
    """'verlet:0.5,omelyan-2 4 fs' -> the rows as written (:meth:`~..core.rows.Row.parse` reads both); a row without
    a step is refused here, an unknown method when the study is configured."""
    rows = [item.strip() for item in text.split(",") if item.strip()]
    for item in rows:
        try:
            Row.parse(item)
        except ValueError as exc:
            if "no step" in str(exc):
                raise argparse.ArgumentTypeError(f"{item!r} is not METHOD:STEP_FS (e.g. verlet:0.5)") from None
    return rows


def build_parser(prog: str = "symprk equipartition"):
    ap = argparse.ArgumentParser(prog=prog, description=__doc__)
    add_study_arguments(ap, quick="64 waters, short runs: seconds, large error bars", out="equipartition-results",
                        workers="worker processes (each runs one NVE run at a time)",
                        length="NVE length measured per replica")
    ap.add_argument("--models", default=None, help="comma-separated water models (spce, tip3p); default: all (--quick: spce)")
    ap.add_argument("--rows", type=_rows, default=None,
                    help="METHOD:STEP_FS,... (or row labels: 'verlet 2 fs') for every model (rigid:METHOD for the rigid-body engine); "
                         "the reference verlet:0.5 is added")
    return ap


def run(args):
    cfg = presets.quick() if args.quick else presets.full()

    def configure(cfg):
        if args.models:
            wanted = [m.strip() for m in args.models.split(",") if m.strip()]
            unknown = [m for m in wanted if m not in presets.full()["models"]]
            if unknown:
                raise InputError(f"unknown water model(s) {', '.join(unknown)}; known: "
                                 f"{', '.join(presets.full()['models'])}")
            base = presets.full()["models"]
            cfg["models"] = {m: cfg["models"].get(m, base[m]) for m in wanted}
        if args.rows:
            given = [Row.parse(r).label for r in args.rows]
            rows = ([cfg["reference"]] if cfg["reference"] not in given else []) + given
            cfg["models"] = {m: rows for m in cfg["models"]}

    run_study(args, cfg, configure, "openmm_symprk.studies.equipartition.study",
              "openmm_symprk.studies.equipartition.report")
