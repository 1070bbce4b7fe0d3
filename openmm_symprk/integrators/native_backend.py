"""The native backend: catalogue kick/drift methods run by the compiled SymPRKIntegrator plugin.

    from openmm_symprk import NativeSymplecticIntegrator
    integrator = NativeSymplecticIntegrator(2*unit.femtoseconds, "yoshida-4", system=system)

The plugin runs the same kick/drift program as the CustomIntegrator backend (on Reference both give the
same trajectory bit for bit) without CustomIntegrator's per-degree-of-freedom interpreter.  Kernels:
Reference and CPU (one kernel), OpenCL and CUDA (the Common compute source); :mod:`openmm_symprk.plugin`
loads them and says why the backend is unavailable when it is.

With ``temperature=`` the plugin runs the stochastic velocity-rescaling thermostat (:mod:`.thermostat` checks
the options): its events are the THERMOSTAT sub-steps of the resolved method (half events at the ends of the step,
or one at its centre with the step run from its closing kicks), which the plugin runs in order like the kicks and
drifts.  On Reference/CPU the plugin's host code draws the noise and computes
the factor; on OpenCL/CUDA the whole event runs on the device (OpenMM's random numbers, the chi-squared variate
summed there): a step makes no host transfer (``getHostTransfers()`` counts the plugin's own).  The C++ object
holds the settings, so a copy or an integrator read back from XML has them; a State taken with
``getIntegratorParameters=True`` carries the heat-bath energy.  Where the System has no peculiar kinetic energy
(at rest, or moving as a rigid whole) an event changes nothing, and the first such event warns once.

The C++ integrator checks, when a Context is created, that its System has the particle count and the
constraints of ``system=`` (``setExpectedSystem``); its checkpoints carry a signature of the program and
refuse another one; a platform without a kernel fails with a message naming the platforms that have one.
"""
from __future__ import annotations

import openmm as mm

from .. import plugin
from ..methods.resolved import substep_label
from .backend import resolve_for_system
from .base import IntegratorBase
from .options import NATIVE_OPTIONS, IntegratorOptions, check_option_names
from .thermostat import ThermostatSettings, thermostat_settings
from .program import ProgramInfo
from .symplectic import SymplecticIntegrator
from ..support.errors import InputError

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
    a Context of another System is refused), and the options both backends take (:mod:`.options`):
    ``exact_momentum`` (needs ``system=``), ``check_finite``, ``max_speed``, ``groups`` and ``inner_method``, and the
    thermostat's ``temperature``, ``collision_time``, ``thermostat_interval`` and ``random_seed`` (see
    :func:`~openmm_symprk.integrators.thermostat.thermostat_settings`; with groups= it wraps the outer step).
    Raises NativeUnavailableError (with the reason and the fix) when the plugin is unavailable and NativeMethodError
    for implicit and general tableaux, which only the CustomIntegrator backend runs."""

    def __init__(self, stepSize, method="verlet", system=None, backend="native", *, exact_momentum=False,
                 check_finite=True, max_speed=None, groups=None, inner_method=None, temperature=None,
                 collision_time=None, thermostat_interval=None, random_seed=None, thermostat_position=None, **unknown):
        self._check_backend(backend)
        check_option_names(unknown, NATIVE_OPTIONS | {"backend"}, type(self).__name__)
        opts = IntegratorOptions.build(
            type(self).__name__, stepSize, system, exact_momentum=exact_momentum, check_finite=check_finite,
            max_speed=max_speed, groups=groups, inner_method=inner_method)
        self._remember_system(system)
        settings = thermostat_settings(system, temperature=temperature, collision_time=collision_time,
                                       thermostat_interval=thermostat_interval, random_seed=random_seed,
                                       thermostat_position=thermostat_position)
        if _swig is None:
            raise plugin.NativeUnavailableError(f"the native backend is unavailable: {plugin.unavailable_reason()}. "
                                                f"To fix it, {plugin.fix_hint()}.")
        # the native kernels place virtual sites after every drift: no CustomIntegrator caveat
        r = resolve_for_system(type(self).__name__, method, system, opts, skip_checks=("virtualsites",),
                               thermostat=settings, splittings_only="the native backend runs kick/drift splittings and compositions only. "
                                               "Use SymplecticIntegrator(..., backend='custom') for it.")
        subs = r.substeps
        _PluginIntegrator.__init__(self, opts.step_size, [int(s.kind) for s in subs],
                                   [float(s.coefficient) for s in subs], [s.group_mask for s in subs],
                                   [int(s.flags) for s in subs])
        self.setMethodName(r.name)
        self.setExactMomentum(opts.exact_momentum)
        self.setMaxSpeed(opts.max_speed)
        if opts.system is not None:
            self.setExpectedSystem(opts.system.n_particles, r.constraints)
        if settings is not None:
            self._set_thermostat(settings)
        self._set_program(r, opts)

    def _set_program(self, r, options, notes=()):
        """Record the resolved method, the options and what the plugin reports of its program."""
        self.resolved = r
        self.options = options
        self.program_info = ProgramInfo(r, r.constraints, int(self.getProgramSignature()),
                                        ("native SymPRKIntegrator plugin", *notes))

    # -- backend hooks -------------------------------------------------------------------------------------
    def _blowup_step(self) -> int:
        return int(self.getBlowUpStep())

    def _clear_blowup(self):
        self.clearBlowUp()

    def _raw_steps_taken(self) -> int:
        return int(self.getStepsTaken())

    def _reset_binding(self):
        """A copy of a 0.2.0 pickle carried no settings of its own (the plugin held them): read them from the plugin."""
        if self.__dict__.get("_thermostat") is None and self.hasThermostat() and self.resolved is not None:
            self._thermostat = self.plugin_thermostat_settings(self.resolved.thermostat_position)

    def _adopt(self, other):
        """Wrap a deserialized SymPRKIntegrator (XmlSerializer gives it as a base openmm.Integrator), which stays valid:
        the cast gives a second SWIG handle that does not own the C++ object, so ``other`` keeps owning it and this
        wrapper keeps ``other`` alive (dropping either one leaves the other usable)."""
        typed = _swig.SymPRKIntegrator.cast(other)
        typed.thisown = False
        self.this = typed.this
        self._wrapped = other

    # -- the thermostat: the plugin is given the settings the integrator holds ----------------------------------------
    def plugin_thermostat_settings(self, position: str):
        """The thermostat's settings as the plugin holds them (an integrator read from XML), with its placement
        ``position`` (None without a thermostat)."""
        if not self.hasThermostat():
            return None
        return ThermostatSettings(temperature=float(self.getThermostatTemperature()),
                                  collision_time=float(_PluginIntegrator.getCollisionTime(self)),
                                  interval=int(_PluginIntegrator.getThermostatInterval(self)),
                                  seed=int(_PluginIntegrator.getRandomNumberSeed(self)), dof=int(self.getThermostatDof()),
                                  keep_rotation=bool(self.getThermostatKeepsRotation()), position=position)

    def _apply_thermostat(self, settings):
        """Give the plugin ``settings``: the temperature at any time, the seed for the next Context, the rest before the
        Context exists (its checkpoints and program signature carry the collision time, interval and degrees of
        freedom)."""
        current = self._thermostat
        if current is None or (current.collision_time, current.interval, current.dof, current.keep_rotation) != \
                (settings.collision_time, settings.interval, settings.dof, settings.keep_rotation):
            try:
                self.setThermostat(settings.temperature, settings.collision_time, settings.interval, settings.dof,
                                   settings.keep_rotation)
            except mm.OpenMMException as exc:
                if "bound" not in str(exc):
                    raise
                raise InputError(f"the native backend cannot change the thermostat's collision time (from "
                                 f"{current.collision_time:g} ps to {settings.collision_time:g} ps) once the integrator "
                                 f"runs a Context: its checkpoints and program signature carry it. Set it before "
                                 f"creating the Context, or create a new integrator") from None
        elif current.temperature != settings.temperature:
            self.setThermostatTemperature(settings.temperature)  # allowed while bound
        _PluginIntegrator.setRandomNumberSeed(self, int(settings.seed))

    def _heat_bath_energy(self) -> float:
        return float(self.getHeatBathEnergy())

    def _thermostat_kinetic_energy(self) -> float:
        return float(self.getThermostatKineticEnergy())

    def _thermostat_peculiar_kinetic_energy(self) -> float:
        return float(self.getThermostatPeculiarKineticEnergy())

    def _skipped_thermostat_events(self) -> int:
        """Events that found no peculiar kinetic energy (IntegratorBase warns once, for both backends)."""
        return int(self.getSkippedThermostatEvents())

    def _still(self) -> bool:
        return bool(self.getLastThermostatEventSkipped())

    # -- conveniences ----------------------------------------------------------------------------------------
    @property
    def force_evals(self) -> int:
        return int(self.getForceEvaluationsPerStep())

    def device_counts(self) -> tuple:
        """(launches, host transfers) the plugin's kernel has made itself since bound: on OpenCL/CUDA its own kernels
        and device copies, and its reads and writes (not OpenMM's force and constraint kernels); (0, 0) on
        Reference/CPU.  How it groups the step's operations into launches: ``setKernelFusion`` (docs/native.md)."""
        return int(self.getKernelLaunches()), int(self.getHostTransfers())

    def substeps(self) -> list:
        """[(label, coefficient)] as the plugin runs them: "drift", "kick", or "kick:<groups>" for a kick of some
        force groups only (multiple time stepping)."""
        out = []
        for i in range(self.getNumSubsteps()):
            mask, c = self.getSubstepForceGroups(i), self.getSubstepCoefficient(i)
            groups = None if mask == -1 else tuple(g for g in range(32) if mask >> g & 1)
            out.append((substep_label(self.getSubstepKind(i), groups), c))
        return out

    def describe(self) -> str:
        return (f"NativeSymplecticIntegrator: {self.method_name}, step {self.getStepSize()}, native backend "
                f"(platforms: {', '.join(plugin.platforms())})\n"
                f"  program: splitting, {sum(s.is_kick_or_drift for s in self.resolved.substeps)} kicks and drifts, constraints="
                f"{'RATTLE' if self.program_info.rattle else 'none'}, force evaluations per step: "
                f"{self.force_evals}, exact momentum: {self.getExactMomentum()}"
                + (f"\n  {self.resolved.describe_levels()}" if self.resolved.is_mts else "")
                + self._describe_thermostat())

    def _describe_thermostat(self) -> str:
        settings = self.thermostat
        if settings is None:
            return ""
        return f"\n  {settings.describe(self.thermostat_position, outer=self.resolved.is_mts)}"


# IntegratorBase.step must come before the plugin's own step in the method resolution order.
assert NativeSymplecticIntegrator.step is IntegratorBase.step
