"""An integrator read back from XML, given its Python class again.

``pickle``, ``copy.copy`` and ``copy.deepcopy`` of the package's integrators already give back the same
class (see :class:`~.base.IntegratorBase`).  Plain ``openmm.XmlSerializer.deserialize`` cannot: it returns
an ``openmm.CustomIntegrator`` (or, for the native plugin, a base ``openmm.Integrator``), without the
blow-up check, the Context checks or ``describe()``.  :func:`restore` turns either into the package's class,
from what the XML carries (the metadata of a CustomIntegrator program; the plugin's method and options).

    integrator = openmm_symprk.deserialize(xml)              # or restore(XmlSerializer.deserialize(xml))
"""
from __future__ import annotations

from dataclasses import replace

import openmm as mm

from .. import plugin
from ..methods.catalogue import methods as catalogue_methods
from ..methods.resolved import resolve
from ..methods.splitting import Splitting
from ..systems.properties import SystemSignature
from . import program
from .custom import CustomSymplecticIntegrator, PRKIntegrator, read_metadata
from .native import NativeSymplecticIntegrator, native_available
from .program import ProgramInfo
from .thermostat import ThermostatSettings

__all__ = ["restore", "deserialize"]


def deserialize(xml: str):
    """``XmlSerializer.deserialize`` for an integrator of this package, returning its class."""
    return restore(mm.XmlSerializer.deserialize(xml))


def restore(integrator):
    """The package's integrator class around ``integrator`` (an OpenMM integrator from XML), which it takes
    over; an integrator that already is one is returned as it is."""
    from .base import IntegratorBase

    if isinstance(integrator, IntegratorBase):
        return integrator
    if isinstance(integrator, mm.CustomIntegrator):
        return _restore_custom(integrator)
    swig = plugin.swig_module()
    if swig is not None and swig.SymPRKIntegrator.isinstance(integrator):
        return _restore_native(integrator)
    if not native_available() and type(integrator) is mm.Integrator:
        raise TypeError("this integrator may be a native SymPRKIntegrator, but the native plugin is unavailable here: "
                        f"{plugin.unavailable_reason()}")
    raise TypeError(f"{type(integrator).__name__} is not an integrator of openmm_symprk (no metadata in its program)")


def _restore_custom(integrator: mm.CustomIntegrator):
    meta = read_metadata(integrator)
    if meta is None:
        raise TypeError("this CustomIntegrator was not compiled by openmm_symprk (its program carries no metadata)")
    catalogue = meta.get("catalogue")
    cls = CustomSymplecticIntegrator if meta.get("class") == "CustomSymplecticIntegrator" else PRKIntegrator
    obj = object.__new__(cls)
    obj._adopt(integrator)
    steps = [obj.getComputationStep(i) for i in range(obj.getNumComputations())]
    names = {obj.getGlobalVariableName(i) for i in range(obj.getNumGlobalVariables())}
    kind = "implicit" if program.NONCONV_VAR in names else (
        "splitting" if not any(var.startswith("symprk_k") for _, var, _ in steps) else "explicit")
    constraints = any(k == mm.CustomIntegrator.ConstrainPositions for k, _, _ in steps) and kind == "splitting"
    options = meta.get("options", {})
    system = meta.get("system")
    catalogue = meta.get("catalogue")
    # a catalogue method is resolved again as it was compiled (its sub-steps, orders, levels); a user tableau's
    # program carries no description of it
    groups = options.get("groups")
    resolved = resolve(catalogue, constraints=constraints, groups=[tuple(g) for g in groups] if groups else None,
                       inner_method=options.get("inner_method") if groups else None) if catalogue else None
    obj.method_name = meta.get("method", "user tableau")
    obj._set_resolved(resolved)
    obj.__dict__.update(
        check_finite=bool(options.get("check_finite", True)), max_speed=float(options.get("max_speed") or 0.0),
        exact_momentum=bool(options.get("exact_momentum", False)),
        compiled_for=SystemSignature(**system) if system else None, _masses=None,
        thermostat=ThermostatSettings(**meta["thermostat"]) if meta.get("thermostat") else None,
        _signature=obj.getGlobalVariable(0),
        program_info=ProgramInfo(kind, constraints, resolved.force_evals if resolved is not None else None,
                                 len(resolved.substeps) if resolved is not None else 0,
                                 bool(options.get("exact_momentum", False)), ["restored from XML"],
                                 signature=int(obj.getGlobalVariable(0)),
                                 evals_per_group=(resolved.evaluations or None) if resolved is not None else None))
    obj._reset_binding()
    return obj


def _restore_native(integrator):
    obj = object.__new__(NativeSymplecticIntegrator)
    obj._adopt(integrator)
    name = obj.getMethodName() or "user splitting"
    expected = obj.getExpectedNumParticles()
    constraints = bool(obj.getExpectedConstraints()) if expected >= 0 else True
    plugin_steps = [(obj.getSubstepKind(i), obj.getSubstepCoefficient(i), obj.getSubstepForceGroups(i),
                     obj.getSubstepFlags(i)) for i in range(obj.getNumSubsteps())]

    def runs_as_plugin(r):
        return [(int(s.kind), float(s.coefficient), s.group_mask, int(s.flags)) for s in r.substeps] == plugin_steps

    # a catalogue method resolved again (exact coefficients) if that is what the plugin runs; otherwise (multiple
    # time stepping, a user splitting) the plugin's sub-steps as they run, with the catalogue's orders if named
    resolved = resolve(name, constraints=constraints) if name in catalogue_methods else None
    if resolved is None or not runs_as_plugin(resolved):
        resolved = resolve(Splitting(obj.substeps()), constraints=constraints, name=name)
        if not runs_as_plugin(resolved):
            raise ValueError(f"the SymPRKIntegrator {name!r} read from XML runs sub-steps {plugin_steps} (kind, "
                             f"coefficient, force groups, flags) whose flags its sequence would not get: it was not "
                             f"built by openmm_symprk")
        if name in catalogue_methods:
            entry = catalogue_methods[name]
            resolved = replace(resolved, entry=entry, order=entry.order, constrained_order=entry.constrained_order,
                               stability=entry.stability)
    obj._set_resolved(resolved)
    obj.__dict__.update(check_finite=True, max_speed=float(obj.getMaxSpeed()), exact_momentum=bool(obj.getExactMomentum()),
                        compiled_for=None)
    obj.program_info.notes.append("restored from XML")
    obj._reset_binding()
    return obj
