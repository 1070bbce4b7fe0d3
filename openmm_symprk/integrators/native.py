"""The native backend: catalogue kick/drift methods run by the compiled SymPRKIntegrator plugin.

    from openmm_symprk import NativeSymplecticIntegrator
    integrator = NativeSymplecticIntegrator(2*unit.femtoseconds, "yoshida-4", system=system)

The plugin runs the same kick/drift program as the CustomIntegrator backend (on Reference both give the
same trajectory bit for bit) without CustomIntegrator's per-degree-of-freedom interpreter.  Kernels:
Reference and CPU (one kernel), OpenCL and CUDA (the Common compute source); :mod:`openmm_symprk.plugin`
loads them and says why the backend is unavailable when it is.

The C++ integrator checks, when a Context is created, that its System has the particle count and the
constraints of ``system=`` (``setExpectedSystem``); its checkpoints carry a signature of the program and
refuse another one; a platform without a kernel fails with a message naming the platforms that have one.
"""
from __future__ import annotations

import openmm as mm

from .. import plugin
from ..methods.catalogue import get_method
from ..methods.respa import evaluations_per_step, kick_label
from ..methods.splitting import DRIFT
from ..systems.checks import validate_system
from ..systems.properties import has_constraints, signature
from .backend import NativeMethodError
from .base import IntegratorBase, check_max_speed, step_size_in_ps
from .mts import describe_levels, kick_masks, mts_splitting
from .program import ProgramInfo
from .symplectic import SymplecticIntegrator

__all__ = ["NativeSymplecticIntegrator", "native_available"]

_swig = plugin.swig_module()
#: The plugin's SWIG class (openmm.Integrator when the plugin is unavailable: the class below then exists,
#: for isinstance checks and documentation, but cannot be instantiated).
_PluginIntegrator = _swig.SymPRKIntegrator if _swig is not None else mm.Integrator


def native_available() -> bool:
    """True if the native plugin is built, matches the installed openmm, and loaded a kernel."""
    return _swig is not None


class NativeSymplecticIntegrator(SymplecticIntegrator, _PluginIntegrator, backend="native"):
    """A catalogue kick/drift method run by the native SymPRKIntegrator plugin (an ``openmm.Integrator``).

    Parameters: those of :class:`~openmm_symprk.integrators.symplectic.SymplecticIntegrator` that apply to
    splittings: ``stepSize``, ``method``, ``system`` (decides the RATTLE sequence -- compositions are taken over
    velocity Verlet under constraints --, is checked for anything that breaks conservation, and is recorded:
    a Context of another System is refused), ``exact_momentum`` (needs ``system=``), ``check_finite`` and
    ``max_speed``.  Raises NativeUnavailableError (with the reason and the fix) when the plugin is unavailable
    and NativeMethodError for implicit and general tableaux, which only the CustomIntegrator backend runs."""

    def __init__(self, stepSize, method="verlet", system=None, backend="native", exact_momentum=False,
                 check_finite=True, max_speed=None, groups=None, inner_method=None):
        self._check_backend(backend)
        if _swig is None:
            raise plugin.NativeUnavailableError(f"the native backend is unavailable: {plugin.unavailable_reason()}. "
                                                f"To fix it, {plugin.fix_hint()}.")
        dt = step_size_in_ps(stepSize)
        m = get_method(method)
        if not m.is_splitting:
            raise NativeMethodError(
                f"method {m.name!r} is a general ({m.family}) PRK tableau; the native backend runs kick/drift "
                f"splittings and compositions only. Use SymplecticIntegrator(..., backend='custom') for it.")
        max_speed = check_max_speed(max_speed)
        if exact_momentum and system is None:
            raise ValueError("exact_momentum=True needs system= (the System the integrator will run): the projection "
                             "is only right for an isolated System, which is checked")
        if system is not None:
            # the native kernels place virtual sites after every drift: no CustomIntegrator caveat
            validate_system(system, f"NativeSymplecticIntegrator({m.name})", exact_momentum, skip=("virtualsites",))
        constraints = True if system is None else has_constraints(system)
        self.mts_levels = None
        if inner_method is not None and groups is None:
            raise ValueError("inner_method= needs groups= (the force groups of the levels of multiple time stepping)")
        if groups is not None:
            splitting, self.mts_levels = mts_splitting(m, groups, inner_method, constraints, system)
        else:
            splitting = m.constrained_splitting if constraints else m.splitting
        coeffs = splitting.coefficients()
        _PluginIntegrator.__init__(self, dt, [1 if label == DRIFT else 0 for label, _ in coeffs],
                                   [float(c) for _, c in coeffs])
        if groups is not None:
            self.setSubsteps([1 if label == DRIFT else 0 for label, _ in coeffs], [float(c) for _, c in coeffs],
                             kick_masks(splitting))
        self.setMethodName(m.name)
        self.setExactMomentum(bool(exact_momentum))
        self.setMaxSpeed(max_speed)
        if system is not None:
            self.setExpectedSystem(system.getNumParticles(), constraints)
        self.method = m
        self.method_name = m.name
        self.splitting = splitting
        self.check_finite = bool(check_finite)
        self.max_speed = max_speed
        self.exact_momentum = bool(exact_momentum)
        self.compiled_for = None if system is None else signature(system)
        per_group = evaluations_per_step(splitting)
        self.program_info = ProgramInfo("splitting", constraints, sum(per_group.values()), len(splitting),
                                        bool(exact_momentum), ["native SymPRKIntegrator plugin"],
                                        signature=int(self.getProgramSignature()),
                                        evals_per_group=per_group if list(per_group) != [None] else None)

    # -- backend hooks -------------------------------------------------------------------------------------
    def _blowup_step(self) -> int:
        return int(self.getBlowUpStep())

    def _clear_blowup(self):
        self.clearBlowUp()

    def _raw_steps_taken(self) -> int:
        return int(self.getStepsTaken())

    def _adopt(self, other):
        """Take over a deserialized SymPRKIntegrator (XmlSerializer gives it as a base openmm.Integrator)."""
        typed = _swig.SymPRKIntegrator.cast(other)
        own = bool(getattr(other, "thisown", False))
        other.thisown = False
        self.this = typed.this
        self.thisown = own

    # -- conveniences ----------------------------------------------------------------------------------------
    @property
    def force_evals(self) -> int:
        return int(self.getForceEvaluationsPerStep())

    def substeps(self) -> list:
        """[(label, coefficient)] as the plugin runs them: "drift", "kick", or "kick:<groups>" for a kick of some
        force groups only (multiple time stepping)."""
        out = []
        for i in range(self.getNumSubsteps()):
            mask = self.getSubstepForceGroups(i)
            if self.getSubstepKind(i) == 1:
                label = DRIFT
            else:
                label = "kick" if mask == -1 else kick_label([g for g in range(32) if mask >> g & 1])
            out.append((label, self.getSubstepCoefficient(i)))
        return out

    def describe(self) -> str:
        return (f"NativeSymplecticIntegrator: {self.method_name}, step {self.getStepSize()}, native backend "
                f"(platforms: {', '.join(plugin.platforms())})\n"
                f"  program: splitting, {self.getNumSubsteps()} kicks and drifts, constraints="
                f"{'RATTLE' if self.program_info.constraints else 'none'}, force evaluations per step: "
                f"{self.force_evals}, exact momentum: {self.getExactMomentum()}"
                + (f"\n  {describe_levels(self.mts_levels, self.program_info.evals_per_group)}" if self.mts_levels else ""))


# IntegratorBase.step must come before the plugin's own step in the method resolution order.
assert NativeSymplecticIntegrator.step is IntegratorBase.step
