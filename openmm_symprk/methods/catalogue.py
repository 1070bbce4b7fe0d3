"""The catalogue of named methods, compiled from the data files in ``openmm_symprk/data``.

``methods`` maps every name (and alias) to a :class:`Method`.  Splittings and compositions carry an
exact kick/drift :class:`~openmm_symprk.methods.splitting.Splitting`; implicit and reference methods carry a
tableau pair only.  Lookups of unknown names raise :class:`UnknownMethodError` with close suggestions; the name of
a thermostat or stochastic integrator (``"langevin"``, ``"baoab"``, ``"nose-hoover"``: ``data/thermostats.toml``) is
told that the package's NVT is a method with ``temperature=``.
"""
from __future__ import annotations

import difflib
import math
import re
import tomllib
from collections.abc import Mapping
from dataclasses import dataclass, field
from functools import cached_property
from importlib import resources

import numpy as np

from .splitting import DRIFT, KICK, Splitting, compose
from .tableau import PRKTableau
from ..support.errors import InputError

FAMILIES = ("splitting", "composition", "implicit", "reference")
#: The Hamiltonians a method's order holds for: any separable H = T(p) + V(q), or only those with a quadratic
#: kinetic energy T = p.M^-1.p/2 (all of MD; Runge-Kutta-Nystrom order conditions).
HAMILTONIANS = ("separable", "quadratic-kinetic")


class UnknownMethodError(KeyError, InputError):
    """An integrator name that is not in the catalogue."""

    def __str__(self):  # KeyError quotes its message; show it plainly.
        return self.args[0]


@dataclass(frozen=True)
class Method:
    name: str
    title: str
    order: int
    constrained_order: int | None  # order measured under RATTLE constraints (None: not a splitting)
    hamiltonian: str  # the Hamiltonians its order holds for, one of HAMILTONIANS
    family: str  # one of FAMILIES
    stability: float | None  # largest stable h*omega on the harmonic oscillator
    source: str
    aliases: tuple = ()
    splitting: Splitting | None = field(default=None, compare=False, repr=False)
    base: str | None = None  # compositions: the symmetric base step
    weights: tuple = ()  # compositions: exact weights (strings)
    _tableau_data: dict | None = field(default=None, compare=False, repr=False)

    @property
    def is_splitting(self) -> bool:
        """True if the method is a kick/drift sequence (so it works with constraints, via RATTLE)."""
        return self.splitting is not None

    @cached_property
    def constrained_splitting(self) -> Splitting | None:
        """The sequence compiled for systems with constraints.

        A composition of position Verlet (DKD) loses its order under constraints, because the
        drift-first step with SHAKE projections is not the symmetric RATTLE step; the same weights
        composed over velocity Verlet (RATTLE, KDK) keep the order (docs/theory.md, section 2) at the same
        force-evaluation count.  Every other splitting is compiled as it is."""
        if self.family == "composition" and self.base != "verlet":
            return compose(methods["verlet"].splitting, self.weights)
        return self.splitting

    @cached_property
    def force_evals(self) -> int:
        """Force evaluations per step in a long run (the closing and opening kicks of a splitting share one; an
        implicit pair: per fixed-point iteration), derived from the sequence or the tableau."""
        if self.splitting is not None:
            return self.splitting.force_evaluations()
        return self.tableau().force_evaluations

    @property
    def symplectic(self) -> bool:
        return self.tableau().is_symplectic

    @property
    def stability_per_force_eval(self) -> float | None:
        if self.stability is None:
            return None
        return self.stability / self.force_evals

    def tableau(self, dtype=np.float64) -> PRKTableau:
        if dtype == np.float64:
            return self._tableau64
        return self._make_tableau(dtype)

    @cached_property
    def _tableau64(self) -> PRKTableau:
        return self._make_tableau(np.float64)

    def _make_tableau(self, dtype) -> PRKTableau:
        if self.splitting is not None:
            return PRKTableau.from_splitting(self.splitting, name=self.name, dtype=dtype)
        d = self._tableau_data
        return PRKTableau(d["A"], d["b"], d["A_hat"], d["b_hat"], name=self.name, dtype=dtype)


def _load(filename: str) -> list:
    text = resources.files(__package__).joinpath("data", filename).read_text()
    return tomllib.loads(text)["method"]


def _build(raw: list) -> dict:
    """name -> Method from the data files' entries; ValueError for an unknown family or Hamiltonian, or a listed
    force-evaluation count that is not the one the sequence or tableau gives."""
    entries: dict = {}
    by_name = {r["name"]: r for r in raw}

    def splitting_of(r):
        if "sequence" in r:
            return Splitting((label, c) for label, c in r["sequence"])
        if "base" in r:
            return compose(splitting_of(by_name[r["base"]]), r["weights"])
        return None

    for r in raw:
        stab = r.get("stability")
        if isinstance(stab, str):
            stab = math.inf if stab == "inf" else float(stab)
        m = Method(
            name=r["name"], title=r["title"], order=int(r["order"]),
            constrained_order=r.get("constrained_order"), hamiltonian=r["hamiltonian"], family=r["family"],
            stability=stab, source=r["source"],
            aliases=tuple(r.get("aliases", ())), splitting=splitting_of(r), base=r.get("base"),
            weights=tuple(r.get("weights", ())),
            _tableau_data={k: r[k] for k in ("A", "b", "A_hat", "b_hat")} if "A" in r else None,
        )
        if m.family not in FAMILIES:
            raise ValueError(f"catalogue entry {m.name}: unknown family {m.family!r}; one of {', '.join(FAMILIES)}")
        if m.hamiltonian not in HAMILTONIANS:
            raise ValueError(f"catalogue entry {m.name}: unknown hamiltonian {m.hamiltonian!r}; one of "
                             f"{', '.join(HAMILTONIANS)}")
        if int(r["force_evals"]) != m.force_evals:
            raise ValueError(f"catalogue entry {m.name}: force_evals = {r['force_evals']} is listed, but its "
                             f"{'sequence' if m.is_splitting else 'tableau'} evaluates the forces {m.force_evals} "
                             f"times per step")
        entries[m.name] = m
    return entries


class _Catalogue(Mapping):
    """Read-only name -> Method mapping that also resolves aliases and suggests close names."""

    def __init__(self, entries: dict):
        self._entries = entries
        self._alias = {}
        for m in entries.values():
            for a in (m.name, *m.aliases):
                self._alias[normalise_name(a)] = m.name

    def __getitem__(self, name) -> Method:
        if isinstance(name, Method):
            return name
        if not isinstance(name, str):
            raise UnknownMethodError(f"a method name must be a string, got {name!r}")
        key = self._alias.get(normalise_name(name))
        if key is None:
            hint = thermostat_hint(name)
            if hint:
                raise UnknownMethodError(f"unknown method {name!r}: {hint}")
            raise UnknownMethodError(
                f"unknown method {name!r}.{self.suggest(name)} Known methods: {', '.join(self._entries)} "
                f"(or pass your own PRKTableau to PRKIntegrator).")
        return self._entries[key]

    def suggest(self, name: str, among=None, extra=()) -> str:
        """" Did you mean 'a', 'b'?" for the names close to ``name`` (aliases give their method's name), "" if none.

        ``among``: the methods to suggest from (default: all); ``extra``: more names, outside the catalogue (the
        rigid-body integrators of Euler's equations)."""
        allowed = None if among is None else {m.name for m in among}
        names = {a: m for a, m in self._alias.items() if allowed is None or m in allowed}
        names.update({normalise_name(e): e for e in extra})
        close = difflib.get_close_matches(normalise_name(str(name)), list(names), n=4, cutoff=0.5)
        close = list(dict.fromkeys(names[c] for c in close))
        return f" Did you mean {', '.join(repr(c) for c in close)}?" if close else ""

    def __iter__(self):
        return iter(self._entries)

    def __len__(self):
        return len(self._entries)

    def __contains__(self, name):
        return isinstance(name, str) and normalise_name(name) in self._alias

    def by_family(self, family: str) -> list:
        return [m for m in self._entries.values() if m.family == family]

    def splittings(self) -> list:
        """Every explicit kick/drift method (splittings and compositions)."""
        return [m for m in self._entries.values() if m.is_splitting]


def normalise_name(name: str) -> str:
    """A method name as the catalogue compares names: case, spaces and underscores do not matter."""
    return name.strip().lower().replace("_", "-").replace(" ", "-")


def _thermostat_key(name: str) -> str:
    """A name as thermostat names are compared: lower case, letters and digits only, no trailing "integrator"."""
    key = re.sub(r"[^a-z0-9]", "", name.lower())
    return key[:-len("integrator")] if key.endswith("integrator") and key != "integrator" else key


_THERMOSTATS = {_thermostat_key(n): entry for entry in
                tomllib.loads(resources.files(__package__).joinpath("data", "thermostats.toml").read_text())["thermostat"]
                for n in entry["names"]}


def thermostat_hint(name) -> str:
    """What to do instead, when ``name`` names a thermostat or stochastic integrator rather than a method ("" if it
    does not): give a method and ``temperature=`` (or use OpenMM's integrator of that kind)."""
    entry = _THERMOSTATS.get(_thermostat_key(name)) if isinstance(name, str) else None
    if entry is None:
        return ""
    openmm = f" For {entry['what']} itself, use OpenMM's {entry['openmm']}." if entry["openmm"] else ""
    return (f"that is {entry['what']}, not a symplectic method. This package's NVT is a method with temperature=, "
            f"the package's thermostat (stochastic velocity rescaling, docs/thermostat.md), e.g. "
            f"SymplecticIntegrator(step, \"verlet\", system=system, temperature=300*unit.kelvin); `symprk methods` "
            f"lists the methods.{openmm}")


methods = _Catalogue(_build(_load("splittings.toml") + _load("tableaux.toml")))


def get_method(name) -> Method:
    """The catalogue entry for ``name`` (aliases accepted); UnknownMethodError with suggestions."""
    return methods[name]


def format_table(entries=None) -> str:
    """The catalogue as a plain-text table (what ``symprk methods`` prints)."""
    entries = list(entries or methods.values())
    head = (f"{'name':24s} {'order':>5s} {'family':12s} {'hamiltonian':17s} {'f/step':>6s} {'stab h*w':>9s} "
            f"{'per eval':>8s}  title")
    lines = [head, "-" * len(head)]
    for m in entries:
        stab = "-" if m.stability is None else ("inf" if math.isinf(m.stability) else f"{m.stability:.4f}")
        per = m.stability_per_force_eval
        per = "-" if per is None else ("inf" if math.isinf(per) else f"{per:.3f}")
        lines.append(f"{m.name:24s} {m.order:5d} {m.family:12s} {m.hamiltonian:17s} {m.force_evals:6d} {stab:>9s} "
                     f"{per:>8s}  {m.title}")
    return "\n".join(lines)


__all__ = ["Method", "methods", "get_method", "format_table", "normalise_name", "thermostat_hint", "UnknownMethodError",
           "FAMILIES", "HAMILTONIANS", "KICK", "DRIFT"]
