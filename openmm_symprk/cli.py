"""The ``symprk`` command: demo, methods, check, info, observe (a trajectory's water observables), and the
studies (bench, conservation, speed, equipartition, fidelity, drift).

Every error the user can cause (a bad name, file, platform, value, a blow-up) ends in one line on stderr
and a non-zero exit status; only a bug shows a traceback.
"""
from __future__ import annotations

import argparse
import sys

from .studies.core.cli import positive, run_command


class CommandError(Exception):
    """A user-facing error of a sub-command: printed as one line, exit status 2."""


def _platform_name(name: str) -> str:
    import openmm as mm

    names = [mm.Platform.getPlatform(i).getName() for i in range(mm.Platform.getNumPlatforms())]
    if name not in names:
        raise CommandError(f"unknown OpenMM platform {name!r}; this installation has {', '.join(names)}")
    return name


def _cmd_demo(args):
    from .studies.demo import run_demo

    run_demo(methods=args.method, n_waters=args.waters, steps=args.steps, step_fs=args.step_fs,
             platform=None if args.platform is None else _platform_name(args.platform), backend=args.backend)


def _cmd_methods(args):
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


def _cmd_check(args):
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


def _cmd_info(args):
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


def build_parser():
    p = argparse.ArgumentParser(prog="symprk", description="Symplectic PRK integrators for OpenMM")
    sub = p.add_subparsers(dest="command", required=True)

    d = sub.add_parser("demo", help="spinning rigid-water cluster: conservation vs OpenMM's Verlet and Langevin")
    d.add_argument("--method", nargs="+", default=None,
                   help="catalogue names, each an NVE row beside OpenMM's Verlet (default: the demo's rows)")
    d.add_argument("--waters", type=positive(int), default=64)
    d.add_argument("--steps", type=positive(int), default=2000)
    d.add_argument("--step-fs", type=positive(float), default=2.0)
    d.add_argument("--platform", default=None, help="default: CPU (Reference where CPU is missing)")
    d.add_argument("--backend", default="auto", choices=("auto", "native", "custom"))
    d.set_defaults(func=_cmd_demo)

    m = sub.add_parser("methods", help="print the catalogue (or details of named methods)")
    m.add_argument("names", nargs="*")
    m.set_defaults(func=_cmd_methods)

    c = sub.add_parser("check", help="check a user tableau file (JSON/TOML with A, b, A_hat, b_hat)")
    c.add_argument("file")
    c.set_defaults(func=_cmd_check)

    i = sub.add_parser("info", help="versions, platforms and backends")
    i.add_argument("--require-native", metavar="PLATFORMS",
                   help="exit with status 2 unless the native plugin serves these platforms (comma-separated)")
    i.set_defaults(func=_cmd_info)

    for name, text in DELEGATED_HELP.items():
        sub.add_parser(name, help=text)
    return p


#: sub-commands whose own argument parser lives in another module (argv passed through untouched)
DELEGATED = {"bench": "openmm_symprk.studies.bench.cli", "conservation": "openmm_symprk.studies.conservation_table",
             "speed": "openmm_symprk.studies.native_speed", "gpucheck": "openmm_symprk.studies.gpucheck",
             "equipartition": "openmm_symprk.studies.equipartition.cli", "fidelity": "openmm_symprk.studies.fidelity.cli",
             "nvt": "openmm_symprk.studies.nvt.cli", "drift": "openmm_symprk.studies.drift.cli",
             "observe": "openmm_symprk.analysis.cli"}
DELEGATED_HELP = {"bench": "work-precision and stability sweeps (symprk bench --help)",
                  "conservation": "conservation table: platform x method x projection (symprk conservation --help)",
                  "speed": "native backend vs OpenMM's VerletIntegrator, time per step (symprk speed --help)",
                  "gpucheck": "the native backend on CUDA: same program, conservation, speed (needs a GPU)",
                  "equipartition": "rigid water: T_rot - T_trans per method and step (symprk equipartition --help)",
                  "fidelity": "rigid water: diffusion, reorientation, omega ACF, g(r), energies per integrator, step and "
                              "thermostat (symprk fidelity --help)",
                  "nvt": "thermostat: cost vs LangevinMiddleIntegrator, effective-energy drift (symprk nvt --help)",
                  "drift": "energy drift over replicas, paired rows, verdict at 3 SE: hmr, exact-momentum, nvt "
                           "(symprk drift --help)",
                  "observe": "water observables of any trajectory (diffusion, reorientation, omega ACF, T_trans/T_rot, "
                             "g(r)) with errors (symprk observe --help)"}


def main(argv=None):
    argv = sys.argv[1:] if argv is None else list(argv)
    if argv and argv[0] in DELEGATED:
        import importlib

        from .support import MissingDependencyError

        try:  # a study's module may need an extra (matplotlib, scipy, ...): say which, in one line
            return importlib.import_module(DELEGATED[argv[0]]).main(argv[1:]) or 0
        except MissingDependencyError as exc:
            print(f"symprk {argv[0]}: error: {exc}", file=sys.stderr)
            return 2
    args = build_parser().parse_args(argv)
    return run_command(f"symprk {args.command}", lambda: args.func(args), (CommandError,))


if __name__ == "__main__":
    sys.exit(main())
