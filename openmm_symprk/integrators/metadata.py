"""The description a CustomIntegrator program of this package carries of itself, written and read back.

OpenMM's XML of a CustomIntegrator keeps its computations and variables, nothing of Python.  So the program carries,
in the name of one global variable (:data:`META_PREFIX` + hex JSON), what built it: the class, the method (its
name; the catalogue name, or, for a method outside the catalogue, its description,
:mod:`openmm_symprk.methods.description`), the options (:class:`~.options.IntegratorOptions`), the facts of
``system=`` and the thermostat's settings.  :func:`.restore.restore` resolves and compiles the method again from
it, and checks the program it gets against the one it read.

An option at its default value is not written where the metadata of earlier versions did not have it
(``constraints``, ``tolerance``, ``max_iterations``, ``allow_nonsymplectic``; the thermostat of an NVE program):
the programs of those options keep their XML, bit for bit (tests/integrators/test_golden_programs.py).
"""
from __future__ import annotations

import json

import openmm as mm
import openmm.unit as unit

from ..methods.description import describe, from_description
from ..methods.resolved import ResolvedMethod, resolve
from ..systems.properties import SystemSignature
from .options import DEFAULT_MAX_ITERATIONS, DEFAULT_TOLERANCE, IntegratorOptions
from .thermostat import ThermostatSettings
from ..support.errors import InputError

__all__ = ["META_PREFIX", "metadata", "add_metadata", "read_metadata", "methods_of", "options_of", "thermostat_of",
           "massless_particles", "massless_of"]

#: Prefix of the global variable whose name carries the program's metadata (hex JSON).
META_PREFIX = "symprk_meta_"


def massless_particles(system: mm.System) -> tuple:
    """The indices of the System's massless particles (virtual sites, frozen atoms)."""
    return tuple(i for i in range(system.getNumParticles()) if system.getParticleMass(i).value_in_unit(unit.dalton)
                 == 0)


def metadata(class_name: str, method, resolved: ResolvedMethod, options: IntegratorOptions,
             thermostat: ThermostatSettings | None = None, massless=()) -> dict:
    """The metadata of a program of ``class_name`` compiled from ``method`` (as given), resolved as ``resolved``,
    with ``options``, the ``thermostat``'s settings as created and the System's ``massless`` particles (written where
    there are some: the thermostat's per-DOF mask leaves them out)."""
    sig = options.system
    meta = {"class": class_name, "method": resolved.name,
            "catalogue": resolved.entry.name if resolved.entry is not None else None,
            "options": {"exact_momentum": options.exact_momentum, "check_finite": options.check_finite,
                        "max_speed": options.max_speed,
                        "groups": None if resolved.groups is None else [list(g) for g in resolved.groups],
                        "inner_method": resolved.inner_name},
            "system": None if sig is None else {"n_particles": sig.n_particles, "constraints": sig.constraints,
                                                "virtual_sites": sig.virtual_sites, "total_mass": sig.total_mass,
                                                "masses_digest": sig.masses_digest}}
    given = {"constraints": (options.constraints, None), "tolerance": (options.tolerance, DEFAULT_TOLERANCE),
             "max_iterations": (options.max_iterations, DEFAULT_MAX_ITERATIONS),
             "allow_nonsymplectic": (options.allow_nonsymplectic, False)}
    meta["options"].update({k: value for k, (value, default) in given.items() if value != default})
    if thermostat is not None:
        meta["thermostat"] = thermostat.as_dict()
    if massless and meta["system"] is not None:
        meta["system"]["massless"] = list(massless)
    if resolved.entry is None:
        meta["description"] = describe(method)
    if resolved.is_mts:
        inner = method if options.inner_method is None else options.inner_method
        if resolve(inner).entry is None:
            meta["inner_description"] = describe(inner)
    return meta


def add_metadata(integrator: mm.CustomIntegrator, meta: dict) -> None:
    """Append the global variable that carries ``meta`` (after the program, whose signature leaves it out)."""
    integrator.addGlobalVariable(META_PREFIX + json.dumps(meta, separators=(",", ":")).encode().hex(), 0.0)


def read_metadata(integrator: mm.CustomIntegrator) -> dict | None:
    """The metadata a program of this package carries in a global variable name, or None."""
    for i in range(integrator.getNumGlobalVariables()):
        name = integrator.getGlobalVariableName(i)
        if name.startswith(META_PREFIX):
            try:
                return json.loads(bytes.fromhex(name[len(META_PREFIX):]).decode())
            except ValueError:
                return None
    return None


def methods_of(meta: dict):
    """(method, inner method or None) to resolve again: catalogue names or the methods described."""
    if meta.get("catalogue"):
        method = meta["catalogue"]
    elif "description" in meta:
        method = from_description(meta["description"])
    else:
        raise InputError(f"the program of {meta.get('method')!r} does not describe its method (it is not in the "
                         f"catalogue, and the openmm_symprk that wrote it did not record user methods): create the "
                         f"integrator again from its method")
    options = meta.get("options", {})
    if "inner_description" in meta:
        return method, from_description(meta["inner_description"])
    return method, options.get("inner_method") if options.get("groups") else None


def options_of(meta: dict, step_size: float, inner_method) -> IntegratorOptions:
    """The :class:`~.options.IntegratorOptions` the metadata records (``step_size`` in ps: the program's)."""
    options = meta.get("options", {})
    system = {k: v for k, v in (meta.get("system") or {}).items() if k != "massless"}
    groups = options.get("groups")
    return IntegratorOptions(
        step_size, SystemSignature(**system) if system else None, bool(options.get("exact_momentum", False)),
        bool(options.get("check_finite", True)), float(options.get("max_speed") or 0.0),
        tuple((int(g), int(n)) for g, n in groups) if groups else None, inner_method, options.get("constraints"),
        bool(options.get("allow_nonsymplectic", False)), float(options.get("tolerance", DEFAULT_TOLERANCE)),
        int(options.get("max_iterations", DEFAULT_MAX_ITERATIONS)))


def massless_of(meta: dict) -> tuple:
    """The massless particles the metadata records (none where it records none, as earlier versions wrote it)."""
    return tuple(int(i) for i in (meta.get("system") or {}).get("massless", ()))


def thermostat_of(meta: dict) -> ThermostatSettings | None:
    """The thermostat's settings the metadata records (as the integrator was created), or None (NVE)."""
    return ThermostatSettings(**meta["thermostat"]) if meta.get("thermostat") else None
