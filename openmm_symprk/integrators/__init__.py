"""The OpenMM integrators, on two backends sharing one base (:mod:`.base`).

* :class:`SymplecticIntegrator` -- a catalogue method by name; builds a :class:`NativeSymplecticIntegrator`
  (:mod:`.native_backend`, the compiled plugin) or a :class:`CustomSymplecticIntegrator` (:mod:`.custom_backend`, a
  CustomIntegrator program), see :mod:`.backend`;
* :class:`PRKIntegrator` -- any PRK tableau pair or kick/drift splitting (CustomIntegrator program);
* :mod:`.options` checks the keyword options once; :mod:`.program` compiles the programs, :mod:`.projection` the
  exact-momentum kicks, :mod:`.thermostat_program` the thermostat's events; :mod:`.metadata` is what a program
  stores of itself and :mod:`.restore` gives an integrator read from XML its class back.

Both backends take the options checked once (:class:`.options.IntegratorOptions`, kept as ``integrator.options``)
and the method resolved once for the System (:func:`.backend.resolve_for_system`, kept as ``integrator.resolved``);
``integrator.program_info`` holds the facts of the compiled program.
"""
from .backend import BackendWarning, NativeMethodError, NativeUnavailableError, PlacementWarning, choose_backend
from .base import (CheckpointMismatchError, ConvergenceWarning, IntegratorBase, SimulationBlowUpError,
                   SystemMismatchError, step_size_in_ps)
from .custom_backend import CustomSymplecticIntegrator, PRKIntegrator, TimeWarning, VirtualSitesError
from .native_backend import NativeSymplecticIntegrator, native_available
from ..methods.resolved import ConstraintSupportError
from .options import IntegratorOptions
from .restore import deserialize, restore
from .symplectic import SymplecticIntegrator

__all__ = ["SymplecticIntegrator", "PRKIntegrator", "CustomSymplecticIntegrator", "NativeSymplecticIntegrator",
           "IntegratorBase", "choose_backend", "native_available", "restore", "deserialize", "SimulationBlowUpError",
           "ConvergenceWarning", "SystemMismatchError", "CheckpointMismatchError", "ConstraintSupportError",
           "BackendWarning", "NativeMethodError", "NativeUnavailableError", "PlacementWarning", "TimeWarning",
           "step_size_in_ps",
           "IntegratorOptions", "VirtualSitesError"]
