"""An integrator read back from XML, given its Python class again.

``pickle``, ``copy.copy`` and ``copy.deepcopy`` of the package's integrators already give back the same
class (see :class:`~.base.IntegratorBase`).  Plain ``openmm.XmlSerializer.deserialize`` cannot: it returns
an ``openmm.CustomIntegrator`` (or, for the native plugin, a base ``openmm.Integrator``), without the
blow-up check, the Context checks or ``describe()``.  :func:`restore` turns either into the package's class,
from what the XML carries.  A CustomIntegrator program carries its metadata (:mod:`.metadata`: class, method,
options, System facts): the method is resolved and compiled again from it, into a scratch program whose signature
must be the one read (global 0), so that the restored integrator's method and program facts are exact.  The plugin
carries its sub-steps, method name and options: the method is resolved again and checked against the sub-steps.

    integrator = openmm_symprk.deserialize(xml)              # or restore(XmlSerializer.deserialize(xml))
"""
from __future__ import annotations

from dataclasses import replace

import openmm as mm
import openmm.unit as unit

from .. import plugin
from ..methods.catalogue import methods as catalogue_methods
from ..methods.resolved import EventPhase, SubstepKind, method_steps, placement_of, resolve
from ..methods.splitting import Splitting
from . import program
from .backend import resolve_for_system
from .base import IntegratorBase
from .custom_backend import CustomSymplecticIntegrator, PRKIntegrator
from .metadata import massless_of, methods_of, options_of, read_metadata, thermostat_of
from .native_backend import NativeSymplecticIntegrator, native_available
from .options import IntegratorOptions
from ..support.errors import InputError

__all__ = ["restore", "deserialize"]


def deserialize(xml: str):
    """``XmlSerializer.deserialize`` for an integrator of this package, returning its class."""
    return restore(mm.XmlSerializer.deserialize(xml))


def restore(integrator):
    """The package's integrator class around ``integrator`` (an OpenMM integrator from XML); an integrator that
    already is one is returned as it is.  Both wrap the same C++ integrator and ``integrator`` stays valid whether
    the result is kept or not (using it directly only skips the package's checks); keep the result to have them."""
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
    """The class, method and options of the metadata; the method resolved and compiled again from them, into a
    scratch CustomIntegrator whose signature must be the program's (global 0): the facts are then exact."""
    meta = read_metadata(integrator)
    if meta is None:
        raise TypeError("this CustomIntegrator was not compiled by openmm_symprk (its program carries no metadata)")
    cls = CustomSymplecticIntegrator if meta.get("class") == "CustomSymplecticIntegrator" else PRKIntegrator
    method, inner = methods_of(meta)
    options = options_of(meta, integrator.getStepSize().value_in_unit(unit.picosecond), inner)
    settings = thermostat_of(meta)
    resolved = resolve_for_system(cls.__name__, method, None, options, name=meta.get("method"), thermostat=settings)
    has_sites = options.system.virtual_sites if options.system is not None else True
    info = program.compile_program(mm.CustomIntegrator(options.step_size), resolved, options, has_sites, settings)
    stored = integrator.getGlobalVariable(0)
    if stored != info.signature:
        raise InputError(f"this {cls.__name__}({resolved.name}) program is not the one its metadata compiles to (its "
                         f"signature {stored:.0f}, recompiled {info.signature}): it was written by another version "
                         f"of openmm_symprk or edited. Create the integrator again with the options it was built with")
    obj = object.__new__(cls)
    obj._adopt(integrator)
    obj._set_program(resolved, options, replace(info, notes=(*info.notes, "restored from XML")))
    obj.__dict__.update(_masses=None, _massless=massless_of(meta))
    # the program holds the temperature and collision time as they were last set (the metadata: as created)
    if settings is not None:
        obj._thermostat = obj.program_thermostat_settings(settings)
    obj._reset_binding()
    obj._forget_run_state()
    return obj


def _restore_native(integrator):
    obj = object.__new__(NativeSymplecticIntegrator)
    obj._adopt(integrator)
    name = obj.getMethodName() or "user splitting"
    expected = obj.getExpectedNumParticles()
    constraints = bool(obj.getExpectedConstraints()) if expected >= 0 else True
    plugin_steps = [(obj.getSubstepKind(i), obj.getSubstepCoefficient(i), obj.getSubstepForceGroups(i),
                     obj.getSubstepFlags(i)) for i in range(obj.getNumSubsteps())]
    # the thermostat's placement, read back from the phases its events' flags name
    position = placement_of(EventPhase.of_flags(flags) for kind, _, _, flags in plugin_steps
                            if kind == SubstepKind.THERMOSTAT)

    def runs_as_plugin(r):
        return [(int(s.kind), float(s.coefficient), s.group_mask, int(s.flags)) for s in r.substeps] == plugin_steps

    # a catalogue method resolved again (exact coefficients) if that is what the plugin runs; otherwise (multiple
    # time stepping, a user splitting) the plugin's sub-steps as they run, with the catalogue's orders if named
    resolved = resolve(name, constraints=constraints, thermostat_position=position) if name in catalogue_methods else None
    if resolved is None or not runs_as_plugin(resolved):
        resolved = resolve(Splitting(method_steps(obj.substeps(), position)), constraints=constraints, name=name,
                           thermostat_position=position)
        if not runs_as_plugin(resolved):
            raise InputError(f"the SymPRKIntegrator {name!r} read from XML runs sub-steps {plugin_steps} (kind, "
                             f"coefficient, force groups, flags) that its sequence would not get: it was not built by "
                             f"this version of openmm_symprk (0.3.0 runs the middle placement's step from its closing "
                             f"kicks), or not by openmm_symprk. Create the integrator again with its method and options")
        if name in catalogue_methods:
            entry = catalogue_methods[name]
            resolved = replace(resolved, entry=entry, order=entry.order, constrained_order=entry.constrained_order,
                               stability=entry.stability)
    # the plugin holds these options; check_finite is Python's (True), system= is held as the expected particle count
    settings = obj.plugin_thermostat_settings(position)
    options = IntegratorOptions(float(obj.getStepSize().value_in_unit(unit.picosecond)),
                                exact_momentum=bool(obj.getExactMomentum()), max_speed=float(obj.getMaxSpeed()))
    obj._thermostat = settings
    obj._set_program(resolved, options, notes=("restored from XML",))
    obj._reset_binding()
    return obj
