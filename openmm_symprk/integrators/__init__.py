"""The OpenMM integrators, on two backends sharing one base (:mod:`.base`).

* :class:`SymplecticIntegrator` -- a catalogue method by name; builds a :class:`NativeSymplecticIntegrator`
  (the compiled plugin) or a :class:`CustomSymplecticIntegrator` (a CustomIntegrator program), see
  :mod:`.backend`;
* :class:`PRKIntegrator` -- any PRK tableau pair or kick/drift splitting (CustomIntegrator program);
* :mod:`.program` compiles the programs, :mod:`.projection` the exact-momentum kicks,
  :mod:`.convergence` measures orders of compiled integrators, :mod:`.restore` gives an integrator read
  from XML its class back.

Both backends take the method resolved once (:func:`openmm_symprk.methods.resolved.resolve`, called by
:func:`.backend.prepare` together with the option checks they share) and keep it as ``integrator.resolved``.
"""
from .backend import BackendWarning, NativeMethodError, NativeUnavailableError, choose_backend
from .base import (CheckpointMismatchError, ConvergenceWarning, IntegratorBase, SimulationBlowUpError,
                   SystemMismatchError, step_size_in_ps)
from .custom import CustomSymplecticIntegrator, PRKIntegrator, TimeWarning
from .native import NativeSymplecticIntegrator, native_available
from ..methods.resolved import ConstraintSupportError
from .restore import deserialize, restore
from .symplectic import SymplecticIntegrator

__all__ = ["SymplecticIntegrator", "PRKIntegrator", "CustomSymplecticIntegrator", "NativeSymplecticIntegrator",
           "IntegratorBase", "choose_backend", "native_available", "restore", "deserialize", "SimulationBlowUpError",
           "ConvergenceWarning", "SystemMismatchError", "CheckpointMismatchError", "ConstraintSupportError",
           "BackendWarning", "NativeMethodError", "NativeUnavailableError", "TimeWarning", "step_size_in_ps"]
