"""The ``symprk`` command: demo, methods, check, info, and the studies (bench, conservation)."""
from __future__ import annotations

import argparse
import sys


def _cmd_demo(args):
    from .demo import run_demo

    run_demo(methods=args.method, n_waters=args.waters, steps=args.steps, step_fs=args.step_fs,
             platform=args.platform)


def _cmd_methods(args):
    from .catalogue import format_table, methods

    entries = [methods[n] for n in args.names] if args.names else None
    print(format_table(entries))
    if args.names:
        for n in args.names:
            m = methods[n]
            print(f"\n{m.name}: {m.title}\n  source: {m.source}\n  aliases: {', '.join(m.aliases) or '-'}"
                  f"\n  order under RATTLE constraints: {m.constrained_order or 'not available (no constraints)'}"
                  f"\n  {m.tableau().summary()}")
            if m.splitting is not None:
                print("  sequence (applied left to right):")
                for label, c in m.splitting.coefficients():
                    print(f"    {label:5s} {c: .17f}")


def _cmd_check(args):
    """Check a user tableau pair given as a JSON or TOML file with A, b, A_hat, b_hat."""
    import json
    import tomllib

    from .tableau import PRKTableau

    text = open(args.file, "rb").read()
    data = tomllib.loads(text.decode()) if args.file.endswith(".toml") else json.loads(text)
    tab = PRKTableau(data["A"], data["b"], data.get("A_hat", data["A"]), data.get("b_hat", data["b"]),
                     name=args.file)
    print(tab.summary())
    print("symplectic for MD (condition (6)):", tab.is_symplectic)
    print("symplectic for any H ((6) and (7)):", tab.is_symplectic_general)
    from .numerics import measure_order, stability_interval

    print(f"largest stable h*omega on the harmonic oscillator: {stability_interval(tab):.4f}")
    orders, _ = measure_order(tab, dtype=float)
    print(f"measured order on Henon-Heiles: {orders[-1]:.2f}")
    return 0 if tab.is_symplectic else 1


def _cmd_info(args):
    import openmm as mm

    import openmm_symprk
    from . import native

    print(f"openmm_symprk {openmm_symprk.__version__}, OpenMM {mm.__version__}")
    details = native.native_details()
    names = [mm.Platform.getPlatform(i).getName() for i in range(mm.Platform.getNumPlatforms())]
    for n in names:
        how = details.get(n, "")
        backend = "native plugin" if how == "native" else f"CustomIntegrator program (native: {how or 'n/a'})"
        print(f"  platform {n:10s} backend for splittings: {backend}")
    auto = "native" if native.native_available() and all(details.get(n) == "native" for n in names) else "custom"
    print(f"  SymplecticIntegrator(backend='auto') gives: {auto} for splittings and compositions, "
          f"custom for implicit and general tableaux")
    print(f"  catalogue: {len(openmm_symprk.methods)} methods (symprk methods)")
    if args.require_native:
        wanted = [p.strip() for p in args.require_native.split(",") if p.strip()]
        missing = [p for p in wanted if details.get(p) != "native"]
        if missing:
            print(f"symprk info: error: the native plugin does not serve {', '.join(missing)} "
                  f"({'; '.join(f'{p}: ' + (details.get(p) or 'no such OpenMM platform here') for p in missing)})",
                  file=sys.stderr)
            return 1


def build_parser():
    p = argparse.ArgumentParser(prog="symprk", description="Symplectic PRK integrators for OpenMM")
    sub = p.add_subparsers(dest="command", required=True)

    d = sub.add_parser("demo", help="spinning rigid-water cluster: conservation vs OpenMM's Verlet")
    d.add_argument("--method", nargs="+", default=["verlet", "yoshida-4"], help="catalogue names")
    d.add_argument("--waters", type=int, default=64)
    d.add_argument("--steps", type=int, default=2000)
    d.add_argument("--step-fs", type=float, default=2.0)
    d.add_argument("--platform", default="Reference")
    d.set_defaults(func=_cmd_demo)

    m = sub.add_parser("methods", help="print the catalogue (or details of named methods)")
    m.add_argument("names", nargs="*")
    m.set_defaults(func=_cmd_methods)

    c = sub.add_parser("check", help="check a user tableau file (JSON/TOML with A, b, A_hat, b_hat)")
    c.add_argument("file")
    c.set_defaults(func=_cmd_check)

    i = sub.add_parser("info", help="versions, platforms and backends")
    i.add_argument("--require-native", metavar="PLATFORMS",
                   help="exit with status 1 unless the native plugin serves these platforms (comma-separated)")
    i.set_defaults(func=_cmd_info)

    for name, text in (("bench", "work-precision and stability sweeps (symprk bench --help)"),
                       ("conservation", "conservation table: platform x method x projection "
                                        "(symprk conservation --help)")):
        sub.add_parser(name, help=text)
    return p


#: sub-commands whose own argument parser lives in another module (argv passed through untouched)
DELEGATED = {"bench": "openmm_symprk.bench.cli", "conservation": "openmm_symprk.conservation_study"}


def main(argv=None):
    argv = sys.argv[1:] if argv is None else list(argv)
    if argv and argv[0] in DELEGATED:
        import importlib

        return importlib.import_module(DELEGATED[argv[0]]).main(argv[1:]) or 0
    args = build_parser().parse_args(argv)
    try:
        rc = args.func(args)
    except Exception as exc:  # a clean message for the known error types, a traceback otherwise
        from .catalogue import UnknownMethodError
        from .tableau import TableauError

        if isinstance(exc, (UnknownMethodError, TableauError, ValueError, TypeError, FileNotFoundError)):
            print(f"symprk: error: {exc}", file=sys.stderr)
            return 2
        raise
    return rc or 0


if __name__ == "__main__":
    sys.exit(main())
