"""``symprk fidelity``: what users compute from a trajectory (diffusion, reorientation, angular-velocity
correlation, structure, energies, equipartition), per integrator, step and thermostat, against Verlet at 0.5 fs
and against Verlet extrapolated to h -> 0."""
from __future__ import annotations

import argparse
import sys

from ..core.cli import add_study_arguments, run_study_command
from . import presets


def build_parser():
    ap = argparse.ArgumentParser(prog="symprk fidelity", description=__doc__)
    add_study_arguments(ap, quick="64 waters, 0.6-ps runs, 2 replicas: seconds, large errors", out="fidelity-results",
                        workers="worker processes (each runs one run at a time)",
                        length="measured length per run (frames every sample_fs)")
    ap.add_argument("--rows", default=None,
                    help="comma-separated labels of the preset rows to run (the reference is always run), "
                         "e.g. 'verlet 2 fs,omelyan-2 4 fs'; default: all")
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

    def configure(cfg):
        if args.rows:
            cfg["rows"] = select_rows(cfg, args.rows)

    return run_study_command("symprk fidelity", args, cfg, configure, "openmm_symprk.studies.fidelity.simulation",
                             "openmm_symprk.studies.fidelity.report")


if __name__ == "__main__":
    sys.exit(main())
