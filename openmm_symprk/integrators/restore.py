"""An integrator read back from XML, given its Python class again.

``pickle``, ``copy.copy`` and ``copy.deepcopy`` of the package's integrators already give back the same
class (see :class:`~.base.IntegratorBase`).  Plain ``openmm.XmlSerializer.deserialize`` cannot: it returns
an ``openmm.CustomIntegrator`` (or, for the native plugin, a base ``openmm.Integrator``), without the
blow-up check, the Context checks or ``describe()``.  :func:`restore` turns either into the package's class,
from what the XML carries (the metadata of a CustomIntegrator program; the plugin's method and options).

    integrator = openmm_symprk.deserialize(xml)              # or restore(XmlSerializer.deserialize(xml))
"""
from __future__ import annotations

import openmm as mm

from .. import plugin
from ..methods.catalogue import get_method
from ..systems.properties import SystemSignature
from . import program
from .custom import CustomSymplecticIntegrator, PRKIntegrator, read_metadata
from .mts import mts_splitting
from .native import NativeSymplecticIntegrator, native_available
from .program import ProgramInfo

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
    method = get_method(catalogue) if catalogue else None
    options = meta.get("options", {})
    system = meta.get("system")
    mts_levels = None
    if options.get("groups") and method is not None:
        mts_levels = mts_splitting(method, [tuple(g) for g in options["groups"]], options.get("inner_method"),
                                   constraints)[1]
    obj.__dict__.update(
        method=method, method_name=meta.get("method", "user tableau"), mts_levels=mts_levels,
        tableau=method.tableau() if method is not None and mts_levels is None else None,
        check_finite=bool(options.get("check_finite", True)), max_speed=float(options.get("max_speed") or 0.0),
        exact_momentum=bool(options.get("exact_momentum", False)),
        compiled_for=SystemSignature(**system) if system else None, _masses=None,
        _signature=obj.getGlobalVariable(0),
        program_info=ProgramInfo(kind, constraints, method.force_evals if method is not None else None,
                                 len(method.splitting) if method is not None and method.is_splitting else 0,
                                 bool(options.get("exact_momentum", False)), ["restored from XML"],
                                 signature=int(obj.getGlobalVariable(0))))
    obj._reset_binding()
    return obj


def _restore_native(integrator):
    obj = object.__new__(NativeSymplecticIntegrator)
    obj._adopt(integrator)
    m = get_method(obj.getMethodName()) if obj.getMethodName() else None
    from ..methods.splitting import Splitting

    splitting = Splitting(obj.substeps())  # force groups of a multiple-time-step method live in the plugin
    expected = obj.getExpectedNumParticles()
    obj.__dict__.update(
        method=m, method_name=obj.getMethodName() or "user splitting", splitting=splitting, check_finite=True,
        mts_levels=None,
        max_speed=float(obj.getMaxSpeed()), exact_momentum=bool(obj.getExactMomentum()), compiled_for=None,
        program_info=ProgramInfo("splitting", bool(obj.getExpectedConstraints()) if expected >= 0 else True,
                                 int(obj.getForceEvaluationsPerStep()), obj.getNumSubsteps(),
                                 bool(obj.getExactMomentum()), ["native SymPRKIntegrator plugin", "restored from XML"],
                                 signature=int(obj.getProgramSignature())))
    obj._reset_binding()
    return obj
