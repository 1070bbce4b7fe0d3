"""The catalogue of named methods, compiled from the data files in ``openmm_symprk/data``.

``methods`` maps every name (and alias) to a :class:`Method`.  Splittings and compositions carry an
exact kick/drift :class:`~openmm_symprk.methods.splitting.Splitting`; implicit and reference methods carry a
tableau pair only.  Lookups of unknown names raise :class:`UnknownMethodError` with close suggestions.
"""
from __future__ import annotations

import difflib
import math
import tomllib
from collections.abc import Mapping
from dataclasses import dataclass, field
from functools import cached_property
from importlib import resources

import numpy as np

from .splitting import DRIFT, KICK, Splitting, compose
from .tableau import PRKTableau

FAMILIES = ("splitting", "composition", "implicit", "reference")


class UnknownMethodError(KeyError, ValueError):
    """An integrator name that is not in the catalogue."""

    def __str__(self):  # KeyError quotes its message; show it plainly.
        return self.args[0]


@dataclass(frozen=True)
class Method:
    name: str
    title: str
    order: int
    constrained_order: int | None  # order measured under RATTLE constraints (None: not a splitting)
    kind: str  # "PRK" (any separable H) or "RKN" (needs quadratic kinetic energy: all of MD)
    family: str
    force_evals: int  # per step in a long run, closing and opening kicks shared
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


def _build() -> dict:
    entries: dict = {}
    raw = _load("splittings.toml") + _load("tableaux.toml")
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
            constrained_order=r.get("constrained_order"), kind=r["kind"], family=r["family"],
            force_evals=int(r["force_evals"]), stability=stab, source=r["source"],
            aliases=tuple(r.get("aliases", ())), splitting=splitting_of(r), base=r.get("base"),
            weights=tuple(r.get("weights", ())),
            _tableau_data={k: r[k] for k in ("A", "b", "A_hat", "b_hat")} if "A" in r else None,
        )
        if m.family not in FAMILIES:
            raise ValueError(f"catalogue entry {m.name}: unknown family {m.family!r}")
        entries[m.name] = m
    return entries


class _Catalogue(Mapping):
    """Read-only name -> Method mapping that also resolves aliases and suggests close names."""

    def __init__(self, entries: dict):
        self._entries = entries
        self._alias = {}
        for m in entries.values():
            for a in (m.name, *m.aliases):
                self._alias[_norm(a)] = m.name

    def __getitem__(self, name) -> Method:
        if isinstance(name, Method):
            return name
        if not isinstance(name, str):
            raise UnknownMethodError(f"a method name must be a string, got {name!r}")
        key = self._alias.get(_norm(name))
        if key is None:
            close = difflib.get_close_matches(_norm(name), list(self._alias), n=4, cutoff=0.5)
            close = list(dict.fromkeys(self._alias[c] for c in close))
            hint = f" Did you mean {', '.join(repr(c) for c in close)}?" if close else ""
            raise UnknownMethodError(
                f"unknown method {name!r}.{hint} Known methods: {', '.join(self._entries)} "
                f"(or pass your own PRKTableau to PRKIntegrator).")
        return self._entries[key]

    def __iter__(self):
        return iter(self._entries)

    def __len__(self):
        return len(self._entries)

    def __contains__(self, name):
        return isinstance(name, str) and _norm(name) in self._alias

    def by_family(self, family: str) -> list:
        return [m for m in self._entries.values() if m.family == family]

    def splittings(self) -> list:
        """Every explicit kick/drift method (splittings and compositions)."""
        return [m for m in self._entries.values() if m.is_splitting]


def _norm(name: str) -> str:
    return name.strip().lower().replace("_", "-").replace(" ", "-")


methods = _Catalogue(_build())


def get_method(name) -> Method:
    """The catalogue entry for ``name`` (aliases accepted); UnknownMethodError with suggestions."""
    return methods[name]


def format_table(entries=None) -> str:
    """The catalogue as a plain-text table (what ``symprk methods`` prints)."""
    entries = list(entries or methods.values())
    head = f"{'name':24s} {'order':>5s} {'family':12s} {'kind':4s} {'f/step':>6s} {'stab h*w':>9s} {'per eval':>8s}  title"
    lines = [head, "-" * len(head)]
    for m in entries:
        stab = "-" if m.stability is None else ("inf" if math.isinf(m.stability) else f"{m.stability:.4f}")
        per = m.stability_per_force_eval
        per = "-" if per is None else ("inf" if math.isinf(per) else f"{per:.3f}")
        lines.append(f"{m.name:24s} {m.order:5d} {m.family:12s} {m.kind:4s} {m.force_evals:6d} {stab:>9s} {per:>8s}  {m.title}")
    return "\n".join(lines)


__all__ = ["Method", "methods", "get_method", "format_table", "UnknownMethodError", "KICK", "DRIFT"]
