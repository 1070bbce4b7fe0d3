"""``symprk fidelity``: what users compute from a trajectory (diffusion, reorientation, angular-velocity
correlation, structure, energies, equipartition), per integrator, step and thermostat, against Verlet at 0.5 fs
and against Verlet extrapolated to h -> 0."""
from __future__ import annotations

import argparse
import sys

from ..core.options import add_study_arguments, run_study
from . import presets
from .rowspec import for_model
from ...support.errors import InputError


#: Former names of presets, still read (with a note on stderr): {old: new}.
RENAMED = {"issue26": "match-3se"}


def preset_name(text: str) -> str:
    """The name of the preset ``text`` names (a former name read as its new one, with a note)."""
    if text in RENAMED:
        print(f"symprk fidelity: --preset {text} is now called --preset {RENAMED[text]}", file=sys.stderr)
        return RENAMED[text]
    return text


def build_parser(prog: str = "symprk fidelity"):
    ap = argparse.ArgumentParser(prog=prog, description=__doc__)
    add_study_arguments(ap, quick="64 waters, 0.6-ps runs, 2 replicas: seconds, large errors", out="fidelity-results",
                        workers="worker processes (each runs one run at a time)",
                        length="measured length per run (frames every sample_fs)")
    ap.add_argument("--rows", default=None,
                    help="comma-separated labels of the preset rows to run (the reference is always run), "
                         "e.g. 'verlet 2 fs,omelyan-2 4 fs'; 'deciding': the preset's rows that decide its answer "
                         "(run first, and on TIP3P); default: all")
    ap.add_argument("--model", choices=("spce", "tip3p"), default=None,
                    help="water model (default spce); its replica states and runs are kept apart")
    ap.add_argument("--preset", type=preset_name, choices=sorted(presets.PRESETS), default="match-3se",
                    help="the study (default match-3se): match-3se (each row against Verlet at 0.5 fs, every "
                         "observable within 3 standard errors; kept as it ran: --report-only remakes its report) or "
                         "frontier (the cost of each family at equal accuracy, with intervals: docs/fidelity.md's "
                         "answer)")
    return ap


def select_rows(cfg: dict, text: str) -> list:
    """The references and the preset rows named in ``text`` (comma-separated labels, written in any order of the
    row grammar, or ``deciding``: the preset's rows that decide its answer, ``cfg["deciding"]``, by default
    :data:`.presets.DECIDING`), in the presets' order."""
    from .rowspec import label

    wanted = []
    for w in (w.strip() for w in text.split(",")):
        if w == "deciding":
            wanted += cfg.get("deciding", presets.DECIDING)
        elif w:
            wanted.append(w)
    labels = [label(r) for r in cfg["rows"]]
    named = []
    for w in wanted:
        try:
            named.append(label(w))
        except ValueError:
            named.append(w)
    unknown = [w for w, lab in zip(wanted, named) if lab not in labels]
    if unknown:
        raise InputError(f"unknown row(s) {', '.join(repr(u) for u in unknown)}; the rows are: {'; '.join(labels)}")
    keep = set(named) | {label(r) for r in (cfg.get("references") or {}).values()} | {labels[0]}
    return [r for r, lab in zip(cfg["rows"], labels) if lab in keep]


def choose_rows(cfg: dict, rows: str | None, replicas: int | None) -> None:
    """Apply --rows (:func:`select_rows`; the preset's per-row replica counts, ``cfg["row_replicas"]``, kept for the
    chosen rows) and --replicas (every row that many: the per-row counts set aside) to ``cfg``."""
    from .rowspec import label

    if rows:
        cfg["rows"] = select_rows(cfg, rows)
        chosen = {label(r) for r in cfg["rows"]}
        if cfg.get("row_replicas"):
            cfg["row_replicas"] = {k: n for k, n in cfg["row_replicas"].items() if label(k) in chosen}
    if replicas is not None:
        cfg.pop("row_replicas", None)


def run(args):
    cfg = presets.quick() if args.quick else presets.PRESETS[args.preset]()

    def configure(cfg):
        if args.model:
            for_model(cfg, args.model)
        choose_rows(cfg, args.rows, args.replicas)

    run_study(args, cfg, configure, "openmm_symprk.studies.fidelity.simulation", "openmm_symprk.studies.fidelity.report")
