"""What every integrator of the package shares, whichever backend runs it.

:class:`IntegratorBase` is a mixin placed in front of an ``openmm.Integrator`` class (the CustomIntegrator
program of :mod:`.custom_backend` or the plugin's SymPRKIntegrator of :mod:`.native_backend`).  It holds, once:

* ``step(n)``: runs the steps and raises :class:`SimulationBlowUpError` naming the first step whose
  velocities stopped being finite (or exceeded ``max_speed``), the method, the step size and the method's
  stability limit; the record is cleared when it is reported, so reloading a good state and going on works;
* ``setStepSize`` with the package's validation, ``describe()``, ``steps_taken``;
* what it runs: ``resolved`` (the :class:`~openmm_symprk.methods.resolved.ResolvedMethod`), ``options`` (the
  checked :class:`~.options.IntegratorOptions`; ``options.system`` is the
  :class:`~openmm_symprk.systems.properties.SystemSignature` of its ``system=``, which each backend checks against
  the Context it is bound to) and ``program_info`` (the facts of the compiled program,
  :class:`~.program.ProgramInfo`);
* copies: ``pickle``, ``copy.copy`` and ``copy.deepcopy`` go through OpenMM's XML serialization (as for
  OpenMM's own integrators) and give back the same Python class with its conveniences.

* the thermostat's settings, held once: ``thermostat`` is a read-only view of one frozen
  :class:`.thermostat.ThermostatSettings` (None: NVE), which the setters replace through one method
  (:meth:`IntegratorBase._set_thermostat`, which gives the backend's program or plugin the new value); and its
  accessors in OpenMM's idiom: ``getTemperature``/``setTemperature``, ``getCollisionTime``/``setCollisionTime``,
  ``getThermostatInterval``, ``setRandomNumberSeed`` (checked), ``computeHeatBathEnergy``,
  ``thermostat_kinetic_energy`` (the kinetic energy at the thermostat point), ``computeSystemTemperature`` (only
  with a thermostat), ``thermostat_position``, ``thermostat_dof`` / ``getThermostatDegreesOfFreedom``.

An integrator never looks up its Context (OpenMM gives it no way to, short of scanning the Python heap): what it
reports comes from its own program or plugin.

Backends implement the hooks ``_blowup_step()``, ``_clear_blowup()``, ``_raw_steps_taken()`` and may
override ``_before_step()`` / ``_after_step()``; with a thermostat, ``_heat_bath_energy()`` (kJ/mol),
``_apply_thermostat(settings)`` (give the program or the plugin these settings: the temperature and collision time,
and the seed a Context takes when it is created), ``_thermostat_kinetic_energy()`` and
``_thermostat_peculiar_kinetic_energy()`` (kJ/mol, after the last event).
"""
from __future__ import annotations

import math
import operator
import warnings
import weakref

import openmm as mm
import openmm.unit as unit

from ..physics.temperature import R_KJ
from ..systems.hydrogens import unconstrained_hydrogen_hint
from .quantities import positive_quantity
from .thermostat import check_seed
from ..support.errors import InputError, SymprkError

__all__ = ["IntegratorBase", "SimulationBlowUpError", "ConvergenceWarning", "SystemMismatchError",
           "CheckpointMismatchError", "step_size_in_ps"]


class SimulationBlowUpError(SymprkError, RuntimeError):
    """The velocities stopped being finite (the step size is beyond the method's stability limit)."""


class ConvergenceWarning(RuntimeWarning):
    """An implicit method's fixed-point iteration hit its iteration cap on some steps."""


class SystemMismatchError(InputError):
    """The integrator was compiled for another System than the one of the Context it runs."""


class CheckpointMismatchError(SymprkError, RuntimeError):
    """A checkpoint written by another integrator program was loaded into this one."""


def step_size_in_ps(step_size) -> float:
    """Validate a step size: a positive time Quantity, or a positive number taken as picoseconds."""
    return positive_quantity(step_size, "step size", unit.picoseconds, "time", "2*unit.femtoseconds")


def _restore(cls, xml: str, state: dict):
    """Rebuild an integrator of ``cls`` from its XML and Python state (pickle, copy, :func:`restore`)."""
    obj = object.__new__(cls)
    obj._adopt(mm.XmlSerializer.deserialize(xml))
    state = dict(state)
    if "thermostat" in state:  # a pickle of 0.2.0, whose settings were the attribute itself
        state["_thermostat"] = state.pop("thermostat")
    obj.__dict__.update(state)
    obj._reset_binding()
    obj._forget_run_state()
    return obj


class IntegratorBase:
    """Mixin of the package's integrators (see the module docstring)."""

    backend: str = ""
    resolved = None  # the ResolvedMethod it runs (openmm_symprk.methods.resolved)
    options = None  # the IntegratorOptions it was built with (.options)
    program_info = None  # the ProgramInfo of its compiled program (.program)
    _thermostat = None  # the one holder of the thermostat's settings (ThermostatSettings; None: NVE)
    #: attributes a copy does not carry (the C++ object, per-Context handles)
    _transient: tuple = ("this", "thisown", "_wrapped", "_system_ref")

    # -- what it runs -----------------------------------------------------------------------------------
    @property
    def method_name(self) -> str:
        return self.resolved.name

    # -- the step ---------------------------------------------------------------------------------
    def step(self, steps):
        """Advance ``steps`` steps; raise SimulationBlowUpError if the simulation blew up."""
        try:
            steps = operator.index(steps)
        except TypeError:
            raise TypeError(f"steps must be a whole number of steps, got {steps!r}") from None
        if steps < 0:
            raise InputError(f"steps must be >= 0, got {steps}")
        self._before_step()
        try:
            result = super().step(steps)
        except mm.OpenMMException as exc:  # CPU/CUDA check coordinates themselves
            if "nan" not in str(exc).lower():
                raise
            self._clear_blowup()
            raise self._blow_up(self._raw_steps_taken() + 1, "positions became NaN") from exc
        if self.options.check_finite:
            bad = self._blowup_step()
            if bad:
                self._clear_blowup()
                raise self._blow_up(bad, self._blowup_what())
        self._after_step()
        self._check_skipped_events()
        return result

    def _check_skipped_events(self):
        """Warn once per integrator where thermostat events found no peculiar kinetic energy to scale."""
        if self.thermostat is None or self.__dict__.get("_warned_no_peculiar"):
            return
        n = self._skipped_thermostat_events()
        if n and self._still():  # (a 1-dof vibration passes through K_pec ~ 0 at its turning points, then goes on)
            self._warned_no_peculiar = True
            kept = "translation and rotation" if self.thermostat.keep_rotation else "translation"
            warnings.warn(
                f"{type(self).__name__}({self.method_name}): {n} thermostat event(s) found no peculiar kinetic energy "
                f"to scale: the velocities are all zero, or one rigid motion (centre-of-mass {kept}), which the "
                f"thermostat keeps, so it cannot bring the system to {self.thermostat.temperature:g} K (velocity "
                f"rescaling scales the motion it finds and makes none). Start the run with velocities drawn at the "
                f"temperature, e.g. context.setVelocitiesToTemperature({self.thermostat.temperature:g}*unit.kelvin).",
                RuntimeWarning, stacklevel=3)

    def _still(self) -> bool:
        """The last thermostat event found no peculiar kinetic energy (a backend that counts skipped events)."""
        return True

    def _skipped_thermostat_events(self) -> int:
        """Thermostat events that did nothing for want of peculiar kinetic energy (a backend that counts them)."""
        return 0

    def _before_step(self):
        """Checks before stepping (a backend's Context checks)."""

    def _after_step(self):
        """Checks after stepping (a backend's warnings)."""

    def _blowup_what(self) -> str:
        if self.options.max_speed:
            return f"velocities became NaN, infinite or faster than {self.options.max_speed:g} nm/ps"
        return "velocities became NaN or infinite"

    def _remember_system(self, system):
        """Keep a weak reference to the System given as ``system=``: what a message names of it (the hydrogens a
        blow-up leaves unconstrained) is read only when needed, and no copy of the System is kept (nor carried into
        copies of the integrator)."""
        self._system_ref = weakref.ref(system) if system is not None else None

    def _given_system(self):
        """The System given as ``system=``, while the caller keeps it (None otherwise, and in a copy)."""
        ref = self.__dict__.get("_system_ref")
        return ref() if ref is not None else None

    def _blow_up(self, step: int, what: str) -> SimulationBlowUpError:
        system = self._given_system()
        step_fs = self.getStepSize().value_in_unit(unit.femtoseconds)
        hint = unconstrained_hydrogen_hint(system, step_fs) if system is not None else ""
        return SimulationBlowUpError(
            f"the simulation blew up at integrator step {step} with method {self.method_name!r} at step size "
            f"{self.getStepSize()} ({self.backend} backend): {what}.{hint} Reduce the step size (largest stable "
            f"h*omega for this method: {self._stability()}), or minimize the energy first. The Context still "
            f"holds the non-finite state: reload a checkpoint, or positions and velocities saved before this "
            f"call, and go on (the blow-up record is cleared).")

    def _stability(self) -> str:
        st = self.resolved.stability
        if st is None:
            return "unknown (not a catalogue method)"
        return "unbounded" if math.isinf(st) else f"{st:.4f}"

    # -- OpenMM overrides ---------------------------------------------------------------------------
    def setStepSize(self, size):
        return super().setStepSize(step_size_in_ps(size))

    # -- conveniences ------------------------------------------------------------------------------
    @property
    def steps_taken(self) -> int:
        """Steps taken since the integrator was bound, or its Context reinitialized (kept in checkpoints)."""
        self._sync_run_state()
        return int(self._raw_steps_taken())

    def _sync_run_state(self):
        """Before the run's values are read between steps: bring them up to what the Context holds now (a backend
        that notices a reinitialized Context or a loaded checkpoint only when it steps)."""

    def describe(self) -> str:
        """The integrator's program: backend, stages, constraint handling, force evaluations per step."""
        raise NotImplementedError

    # -- the thermostat ---------------------------------------------------------------------------------
    @property
    def thermostat(self):
        """The thermostat's settings as the next step runs them (a frozen
        :class:`~openmm_symprk.integrators.thermostat.ThermostatSettings`), None without a thermostat (NVE).  Read-only:
        ``setTemperature``, ``setCollisionTime`` and ``setRandomNumberSeed`` change it."""
        return self._thermostat

    def _set_thermostat(self, settings):
        """Replace the thermostat's settings: the one way they change (the backend's program or plugin is given them)."""
        self._apply_thermostat(settings)
        self._thermostat = settings

    @property
    def has_thermostat(self) -> bool:
        return self._thermostat is not None

    def _require_thermostat(self, what: str):
        """The thermostat's settings (they need no look at the Context); InputError for an NVE integrator."""
        if self._thermostat is None:
            raise InputError(f"{type(self).__name__}({self.method_name}).{what}: this integrator was created without "
                             f"temperature=, so it runs NVE and has no thermostat; create it with e.g. "
                             f"temperature=300*unit.kelvin (and system=) for NVT")
        return self._thermostat

    @property
    def thermostat_dof(self) -> int | None:
        """Degrees of freedom the thermostat samples (None without one): 3 per particle with mass - constraints
        - 3 (centre-of-mass velocity kept) - 3 more for an isolated System (rigid rotation kept)."""
        return None if self.thermostat is None else int(self.thermostat.dof)

    def getThermostatDegreesOfFreedom(self) -> int:
        return int(self._require_thermostat("getThermostatDegreesOfFreedom()").dof)

    def getTemperature(self):
        """The thermostat's target temperature (a Quantity in K)."""
        return self._require_thermostat("getTemperature()").temperature * unit.kelvin

    def setTemperature(self, temperature):
        """Set the target temperature (a Quantity or a number of K); allowed while the integrator runs."""
        self._set_thermostat(self._require_thermostat("setTemperature()").with_temperature(temperature))

    def getCollisionTime(self):
        """The thermostat's collision time tau (a Quantity in ps)."""
        return self._require_thermostat("getCollisionTime()").collision_time * unit.picoseconds

    def setCollisionTime(self, collision_time):
        """Set the collision time tau (a time Quantity or a number of ps): while the integrator runs on the custom
        backend; on the native backend only before its Context exists (tau is part of the checkpoint signature)."""
        self._set_thermostat(self._require_thermostat("setCollisionTime()").with_collision_time(collision_time))

    def getThermostatInterval(self) -> int:
        """The thermostat acts every this many steps."""
        return int(self._require_thermostat("getThermostatInterval()").interval)

    def setRandomNumberSeed(self, seed):
        """OpenMM's setRandomNumberSeed, checked (an int from 0 to 2**31 - 1; 0: a fresh seed each time a Context
        is created).  As in OpenMM it takes effect when the next Context is created."""
        seed = check_seed(seed)
        if self._thermostat is None:
            return super().setRandomNumberSeed(seed)
        self._set_thermostat(self._thermostat.with_seed(seed))  # (which gives the program or the plugin the seed)

    def computeHeatBathEnergy(self):
        """The heat-bath energy (a Quantity in kJ/mol): minus the energy the thermostat gave the system, so that
        total energy + heat-bath energy is conserved up to the integrator's own error (as
        NoseHooverIntegrator.computeHeatBathEnergy).  0 without a thermostat."""
        if self.thermostat is None:
            return 0.0 * unit.kilojoule_per_mole
        self._sync_run_state()
        return float(self._heat_bath_energy()) * unit.kilojoule_per_mole

    def thermostat_kinetic_energy(self):
        """The kinetic energy (a Quantity in kJ/mol) of the velocities just after the last thermostat event: the
        temperature the thermostat samples.  Those are the velocities a State holds after the step of that event, with
        either placement (the middle one runs the step from its closing kicks, so that the State holds the velocities
        of the thermostat point: docs/thermostat.md, "What a user reads as the temperature"), up to the constraint
        corrections of the drift after a middle event.  0 before the first event."""
        self._require_thermostat("thermostat_kinetic_energy()")
        self._sync_run_state()
        return float(self._thermostat_kinetic_energy()) * unit.kilojoule_per_mole

    @property
    def computeSystemTemperature(self):
        """The thermostat's temperature (a Quantity in K) as OpenMM's reporters print it: StateDataReporter asks an
        integrator that has this method instead of computing one from the State's kinetic energy and its own count of
        degrees of freedom, as it does for NoseHooverIntegrator.

        It is 2 K' / (N_f R): K' the peculiar kinetic energy (without the centre-of-mass motion, and the rigid rotation
        of an isolated System) the last thermostat event left, N_f the thermostat's degrees of freedom
        (:attr:`thermostat_dof`).  Those are the velocities a State holds after the step of that event, with either
        placement (docs/thermostat.md, "What a user reads as the temperature"); with ``thermostat_interval`` n > 1 the
        event may lie up to n - 1 steps back, and reports more frequent than every n steps repeat it.  Velocities set
        since (``setVelocities``, ``setVelocitiesToTemperature``) are read at the next event: the integrator cannot
        reach its Context to read them; a checkpoint or a State with integrator parameters brings back the value it
        was saved with.  NaN before the first event of a run.

        Only an integrator with a thermostat has it (``hasattr`` is False for an NVE one), so OpenMM's reporters
        compute an NVE run's temperature from the State, as for VerletIntegrator."""
        if self.__dict__.get("_thermostat") is None:
            raise AttributeError(f"{type(self).__name__}({self.method_name}) runs NVE, without a thermostat, so it has "
                                 f"no computeSystemTemperature: compute the temperature from a State's kinetic energy "
                                 f"(OpenMM's StateDataReporter does so itself)")
        return self._system_temperature

    def _system_temperature(self):
        self._sync_run_state()
        kinetic = float(self._thermostat_peculiar_kinetic_energy())
        if kinetic <= 0:
            return math.nan * unit.kelvin
        return 2 * kinetic / (self.thermostat.dof * R_KJ) * unit.kelvin

    def _thermostat_peculiar_kinetic_energy(self) -> float:
        """K' (kJ/mol) of the last thermostat event: the peculiar kinetic energy it left (0 before the first)."""
        raise NotImplementedError

    @property
    def thermostat_position(self) -> str | None:
        """Where the thermostat sits in the step as it runs: "ends" or "middle" (None without a thermostat)."""
        return None if self.thermostat is None else self.resolved.thermostat_position

    def _heat_bath_energy(self) -> float:
        raise NotImplementedError

    def _thermostat_kinetic_energy(self) -> float:
        raise NotImplementedError(f"{type(self).__name__} cannot report the kinetic energy at the thermostat point")

    def _apply_thermostat(self, settings):
        raise NotImplementedError

    # -- copies ---------------------------------------------------------------------------------------
    def _python_state(self) -> dict:
        """The Python attributes a copy needs (everything but the C++ object and per-Context handles)."""
        return {k: v for k, v in self.__dict__.items() if k not in self._transient}

    def _adopt(self, other):
        """Wrap the C++ object of ``other`` (an openmm.Integrator of the same C++ class), which stays valid: both
        wrappers share SWIG's handle of the object, which deletes it once neither is left."""
        self.this = other.this

    def _reset_binding(self):
        """Forget per-Context facts (a copy is not bound to any Context)."""

    def _forget_run_state(self):
        """Give a copy the run-time values of a fresh integrator (heat bath, step counter, first-step flags), which the
        XML of an integrator that has run carries: a copy with the same settings and seed then runs the trajectory a
        new integrator would (a checkpoint, not a copy, is what continues a run)."""

    def __reduce__(self):
        return _restore, (type(self), mm.XmlSerializer.serialize(self), self._python_state())

    def __copy__(self):
        return _restore(type(self), mm.XmlSerializer.serialize(self), dict(self._python_state()))

    def __deepcopy__(self, memo):
        import copy

        return _restore(type(self), mm.XmlSerializer.serialize(self), copy.deepcopy(self._python_state(), memo))

    # -- hooks ------------------------------------------------------------------------------------------
    def _blowup_step(self) -> int:
        raise NotImplementedError

    def _clear_blowup(self):
        raise NotImplementedError

    def _raw_steps_taken(self) -> int:
        raise NotImplementedError
