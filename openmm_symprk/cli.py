"""The ``symprk`` command, and the one frame every sub-command runs in.

A sub-command is a module with ``build_parser(prog)`` (its options) and ``run(args)`` (its work; an exit status,
None for 0; ``args`` also holds ``command``, ``prog`` and its ``argv``), named in :data:`COMMANDS`: the library's
own (``methods``, ``check``, ``info`` here; ``observe`` in :mod:`openmm_symprk.analysis.cli`) and the studies'
(:mod:`openmm_symprk.studies`).  :func:`main` parses its options and runs it in :func:`run_command`, so every
sub-command has one error policy:

* a user's error (:func:`is_user_error`) is one line ``symprk <name>: error: ...`` on stderr and exit status 2.
  A user's error is an exception raised on purpose: one of the package's own errors
  (:class:`~openmm_symprk.support.errors.SymprkError`: the input checks'
  :class:`~openmm_symprk.support.errors.InputError`, a ValueError; a missing extra named by ``require``,
  :class:`~openmm_symprk.support.MissingDependencyError`; a blow-up; the native plugin missing where it is needed;
  :class:`CommandError` ...), OpenMM refusing its input (``openmm.OpenMMException``), or the OS refusing a file
  the user named (an OSError that carries the file's name);
* anything else is a bug and keeps its traceback: a ValueError of a tuple that does not unpack, an ImportError of
  a typo, a KeyError;
* ``SYMPRK_DEBUG=1`` in the environment, or ``--debug`` anywhere before a ``--``, prints a user's error's
  traceback too (still exit status 2);
* a bad option is argparse's usage and status 2, Ctrl-C status 130.

To refuse an input, raise :class:`~openmm_symprk.support.errors.InputError` (``from ..support.errors import
InputError``; callers that catch ValueError still do), or give a new error class
:class:`~openmm_symprk.support.errors.SymprkError` as a base beside its usual one; a plain ValueError, KeyError or
RuntimeError reads as a bug.
"""
from __future__ import annotations

import argparse
import os
import sys
from dataclasses import dataclass
from importlib import import_module

from .support.errors import SymprkError

__all__ = ["CommandError", "COMMANDS", "is_user_error", "run_command", "build_parser", "main"]


class CommandError(SymprkError):
    """A user's mistake a sub-command finds itself: printed as one line, exit status 2."""


@dataclass(frozen=True)
class Command:
    module: str  # has build_parser(prog) and run(args)
    help: str
    keeps_runs: bool = False  # a study whose finished runs are kept when it is interrupted


#: The sub-commands, in the order ``symprk --help`` lists them.
COMMANDS = {
    "demo": Command("openmm_symprk.studies.demo", "spinning rigid-water cluster: conservation vs OpenMM's Verlet "
                                                  "and Langevin"),
    "methods": Command(__name__, "print the catalogue (or details of named methods)"),
    "check": Command(__name__, "check a user tableau file (JSON/TOML with A, b, A_hat, b_hat)"),
    "info": Command(__name__, "versions, platforms and backends"),
    "observe": Command("openmm_symprk.analysis.cli", "water observables of any trajectory (diffusion, "
                       "reorientation, omega ACF, T_trans/T_rot, g(r)) with errors (symprk observe --help)"),
    "bench": Command("openmm_symprk.studies.bench.cli", "work-precision and stability sweeps (symprk bench --help)",
                     True),
    "conservation": Command("openmm_symprk.studies.platforms.conservation",
                            "conservation table: platform x method x projection (symprk conservation --help)"),
    "speed": Command("openmm_symprk.studies.platforms.speed",
                     "native backend vs OpenMM's VerletIntegrator, time per step (symprk speed --help)"),
    "gpucheck": Command("openmm_symprk.studies.platforms.gpucheck",
                        "the native backend on CUDA: same program, conservation, speed (needs a GPU)"),
    "equipartition": Command("openmm_symprk.studies.equipartition.cli",
                             "rigid water: T_rot - T_trans per method and step (symprk equipartition --help)", True),
    "fidelity": Command("openmm_symprk.studies.fidelity.cli", "rigid water: diffusion, reorientation, omega ACF, "
                        "g(r), energies per integrator, step and thermostat (symprk fidelity --help)", True),
    "nvt": Command("openmm_symprk.studies.nvt.cli",
                   "thermostat: cost vs LangevinMiddleIntegrator, effective-energy drift (symprk nvt --help)"),
    "drift": Command("openmm_symprk.studies.drift.cli", "energy drift over replicas, paired rows, verdict at 3 SE: "
                     "hmr, exact-momentum, nvt (symprk drift --help)", True),
}
#: Other spellings of a sub-command: ``symprk nvt drift ...`` is ``symprk drift nvt ...``.
ALIASES = {("nvt", "drift"): ["drift", "nvt"]}


def is_user_error(exc: BaseException) -> bool:
    """Whether ``exc`` is a user's error (one line, exit status 2) rather than a bug (a traceback): one the package
    raises on purpose (:class:`~openmm_symprk.support.errors.SymprkError`), OpenMM refusing its input, or the OS
    refusing a named file (module docstring)."""
    import openmm as mm

    if isinstance(exc, (SymprkError, mm.OpenMMException)):
        return True
    return isinstance(exc, OSError) and exc.filename is not None


#: The environment variable that shows a user's error's traceback too (as ``--debug`` does).
DEBUG_VARIABLE = "SYMPRK_DEBUG"


def debugging() -> bool:
    """Whether :data:`DEBUG_VARIABLE` asks for tracebacks (set, and not empty, 0, false or no)."""
    return os.environ.get(DEBUG_VARIABLE, "").strip().lower() not in ("", "0", "false", "no")


#: What an interrupted study says.
KEPT = "interrupted (finished runs are kept; run again to continue)"


def run_command(prog: str, action, interrupted: str = "interrupted", debug: bool | None = None) -> int:
    """``action()``'s exit status (None: 0) under the one error policy (module docstring); ``debug`` (default:
    :func:`debugging`) prints a user's error's traceback before its line."""
    try:
        return action() or 0
    except KeyboardInterrupt:
        print(f"{prog}: {interrupted}", file=sys.stderr)
        return 130
    except Exception as exc:
        if not is_user_error(exc):
            raise
        if debugging() if debug is None else debug:
            import traceback

            traceback.print_exc()
        print(f"{prog}: error: {' '.join(str(exc).split())}", file=sys.stderr)
        return 2


# -- the library's own sub-commands ----------------------------------------------------------------------------------
def _methods(args):
    from .methods.catalogue import format_table, methods

    entries = [methods[n] for n in args.names] if args.names else None
    print(format_table(entries))
    for n in args.names or ():
        m = methods[n]
        print(f"\n{m.name}: {m.title}\n  source: {m.source}\n  aliases: {', '.join(m.aliases) or '-'}"
              f"\n  order under RATTLE constraints: {m.constrained_order or 'not available (no constraints)'}"
              f"\n  {m.tableau().summary()}")
        if m.splitting is not None:
            print("  sequence (applied left to right):")
            for label, c in m.splitting.coefficients():
                print(f"    {label:5s} {c: .17f}")


def _read_tableau_file(path: str) -> dict:
    import json
    import tomllib

    try:
        with open(path, "rb") as fh:
            raw = fh.read()
    except OSError as exc:
        raise CommandError(f"cannot read {path}: {exc.strerror or exc}") from None
    try:
        data = tomllib.loads(raw.decode()) if path.endswith(".toml") else json.loads(raw)
    except (ValueError, UnicodeDecodeError) as exc:
        kind = "TOML" if path.endswith(".toml") else "JSON"
        raise CommandError(f"{path} is not valid {kind}: {exc}") from None
    if not isinstance(data, dict) or "A" not in data or "b" not in data:
        found = ", ".join(sorted(data)) if isinstance(data, dict) else type(data).__name__
        raise CommandError(f"{path} must hold a table with A and b (and optionally A_hat, b_hat); found {found}")
    return data


def _check(args):
    """Check a user tableau pair given as a JSON or TOML file with A, b, A_hat, b_hat."""
    from .methods.reference import measure_order
    from .methods.stability import stability_interval
    from .methods.tableau import PRKTableau

    data = _read_tableau_file(args.file)
    tab = PRKTableau(data["A"], data["b"], data.get("A_hat", data["A"]), data.get("b_hat", data["b"]),
                     name=args.file)
    print(tab.summary())
    print("symplectic for MD (condition (6)):", tab.is_symplectic)
    print("symplectic for any H ((6) and (7)):", tab.is_symplectic_general)
    print(f"largest stable h*omega on the harmonic oscillator: {stability_interval(tab):.4f}")
    orders, _ = measure_order(tab, dtype=float)
    print(f"measured order on Henon-Heiles: {orders[-1]:.2f}")
    return 0 if tab.is_symplectic else 1


def _info(args):
    import openmm as mm

    import openmm_symprk

    from . import plugin

    print(f"openmm_symprk {openmm_symprk.__version__}, OpenMM {mm.__version__}")
    details = plugin.details()
    thermostat = set(plugin.thermostat_platforms())
    for n, how in details.items():
        backend = "native plugin" if how == "native" else f"CustomIntegrator program (native: {how})"
        nvt = "native" if n in thermostat else "CustomIntegrator program"
        print(f"  platform {n:10s} backend for splittings: {backend}; NVT thermostat (temperature=): {nvt}")
    auto = "native" if plugin.available() and all(how == "native" for how in details.values()) else "custom"
    print(f"  SymplecticIntegrator(backend='auto') gives: {auto} for splittings and compositions, "
          f"custom for implicit and general tableaux")
    if not plugin.available():
        print(f"  to get the native plugin: {plugin.fix_hint()}")
    print(f"  catalogue: {len(openmm_symprk.catalogue)} methods (symprk methods)")
    if args.require_native:
        wanted = [p.strip() for p in args.require_native.split(",") if p.strip()]
        missing = [p for p in wanted if details.get(p) != "native"]
        if missing:
            raise CommandError(
                f"the native plugin does not serve {', '.join(missing)} "
                f"({'; '.join(f'{p}: ' + (details.get(p) or 'no such OpenMM platform here') for p in missing)})")
    return 0


def build_parser(prog: str = "symprk"):
    """``symprk``'s parser (``prog`` "symprk"), or that of its own sub-command ``prog`` ("symprk methods", ...)."""
    if prog == "symprk methods":
        p = argparse.ArgumentParser(prog=prog, description=COMMANDS["methods"].help)
        p.add_argument("names", nargs="*")
    elif prog == "symprk check":
        p = argparse.ArgumentParser(prog=prog, description=COMMANDS["check"].help)
        p.add_argument("file")
    elif prog == "symprk info":
        p = argparse.ArgumentParser(prog=prog, description=COMMANDS["info"].help)
        p.add_argument("--require-native", metavar="PLATFORMS",
                       help="exit with status 2 unless the native plugin serves these platforms (comma-separated)")
    else:
        p = argparse.ArgumentParser(prog="symprk", description="Symplectic PRK integrators for OpenMM")
        p.add_argument("--debug", action="store_true",
                       help=f"print the traceback of a user's error too (as {DEBUG_VARIABLE}=1 does); a bug's "
                            f"traceback is always printed")
        sub = p.add_subparsers(dest="command", required=True)
        for name, cmd in COMMANDS.items():
            sub.add_parser(name, help=cmd.help, add_help=False)
    return p


def run(args):
    """The library's own sub-commands (``methods``, ``check``, ``info``)."""
    return {"methods": _methods, "check": _check, "info": _info}[args.command](args)


def main(argv=None):
    argv = list(sys.argv[1:] if argv is None else argv)
    end = argv.index("--") if "--" in argv else len(argv)
    debug = "--debug" in argv[:end] or None
    argv = [a for a in argv[:end] if a != "--debug"] + argv[end:]
    name = argv[0] if argv else ""
    prog = f"symprk {' '.join(argv[:2])}" if tuple(argv[:2]) in ALIASES else f"symprk {name}"
    if tuple(argv[:2]) in ALIASES:
        argv = ALIASES[tuple(argv[:2])] + argv[2:]
        name = argv[0]
    if name not in COMMANDS:
        build_parser().parse_args(argv)  # --help, or argparse's usage and exit status 2
        return 2
    cmd = COMMANDS[name]

    def action():
        module = import_module(cmd.module)  # a study may need an extra: MissingDependencyError, one line
        args = module.build_parser(prog).parse_args(argv[1:])
        args.command, args.prog, args.argv = name, prog, argv[1:]
        return module.run(args)

    return run_command(prog, action, KEPT if cmd.keeps_runs else "interrupted", debug)


if __name__ == "__main__":
    sys.exit(main())
