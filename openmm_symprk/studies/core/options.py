"""The studies' command-line options (the command frame, :func:`openmm_symprk.cli.run_command`, runs them):
:func:`positive` numbers, a configuration's counts and positive settings checked (:func:`check_settings`), the options every replica study shares (:func:`add_study_arguments`) and its run and
report (:func:`run_study`: options checked before anything runs)."""
from __future__ import annotations

import argparse
import os
from importlib import import_module

from ...support.errors import InputError

__all__ = ["positive", "check_settings", "add_study_arguments", "run_study"]


def positive(kind=float):
    """An argparse type: a number of type ``kind`` (int or float) that is > 0, refused with the value given."""
    noun = "an integer" if kind is int else "a number"

    def parse(text):
        try:
            value = kind(text)
        except ValueError:
            raise argparse.ArgumentTypeError(f"{text!r} is not {noun}") from None
        if not value > 0:
            raise argparse.ArgumentTypeError(f"must be positive, got {text}")
        return value
    return parse


def check_settings(cfg: dict, counts=(), positive=()) -> None:
    """ValueError naming the first setting of ``cfg`` among ``counts`` that is not a whole number >= 1 (a bool
    neither), or among ``positive`` that is not a number > 0, and its value."""
    for k in counts:
        if isinstance(cfg[k], bool) or int(cfg[k]) < 1:
            raise InputError(f"{k} must be >= 1, got {cfg[k]!r}")
    for k in positive:
        if not float(cfg[k]) > 0:
            raise InputError(f"{k} must be positive, got {cfg[k]!r}")


def add_study_arguments(ap, *, quick: str, out: str | None, workers: str, length: str, default_workers: int = 2,
                        timing: bool = True, out_help: str | None = None) -> None:
    """--quick, --out (default ``out``, or None where the study picks it: ``out_help`` says how), --workers,
    --scheduler, --replicas, --length-ps, --no-timing (with ``timing``), --no-progress and --report-only."""
    ap.add_argument("--quick", action="store_true", help=quick)
    ap.add_argument("--out", default=out, help=f"output folder (default {out_help or out}; finished runs are reused)")
    ap.add_argument("--workers", type=int, default=default_workers, help=f"{workers} (default %(default)s)")
    ap.add_argument("--scheduler", metavar="ADDRESS",
                    help="Dask distributed scheduler address (e.g. tcp://host:8786) instead of local workers; "
                         "needs the 'cluster' extra")
    ap.add_argument("--replicas", type=int, default=None, help="independent replicas per row (default: the study's)")
    ap.add_argument("--length-ps", type=float, default=None, help=f"{length} (default: the study's)")
    if timing:
        ap.add_argument("--no-timing", action="store_true", help="skip the wall-time measurement in turns")
    ap.add_argument("--no-progress", action="store_true", help="no progress bar (for logs and scripts)")
    ap.add_argument("--report-only", action="store_true",
                    help="run nothing: summarise the finished runs in --out (a study still running, or rows run "
                         "with fewer replicas); the planned runs not finished are left out and counted")


def run_study(args, cfg: dict, configure, study: str, report: str) -> None:
    """Apply ``configure(cfg)`` (the study's own options; raises ValueError on a bad one) and the common options,
    run ``run_study`` of the module ``study`` and print ``format_summary`` of the module ``report`` (both imported
    only then, so that ``--help`` and bad options answer at once).  ``args`` needs ``out``, ``workers``,
    ``scheduler``, ``no_progress`` and ``report_only``; ``replicas``, ``length_ps`` and ``no_timing`` apply where
    the command has them (a study without a timing option is not passed ``timing``)."""
    configure(cfg)
    for key in ("replicas", "length_ps"):
        if getattr(args, key, None) is not None:
            cfg[key] = getattr(args, key)
    if args.workers < 1:
        raise InputError(f"--workers must be >= 1, got {args.workers}")
    if os.path.isfile(args.out):
        raise InputError(f"--out {args.out} is a file; give a folder")
    options = {"workers": args.workers, "progress": not args.no_progress, "scheduler": args.scheduler,
               "report_only": args.report_only}
    if hasattr(args, "no_timing"):
        options["timing"] = not args.no_timing
    summary = import_module(study).run_study(cfg, args.out, **options)
    print(import_module(report).format_summary(summary))
    written = sorted(f for f in os.listdir(args.out) if f.endswith((".txt", ".json", ".png")))
    print(f"\nwrote in {args.out}: {', '.join(written)}")
