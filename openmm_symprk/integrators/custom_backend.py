"""The CustomIntegrator backend: programs compiled by :mod:`.program`, run by OpenMM's CustomIntegrator.

    from openmm_symprk import PRKIntegrator, PRKTableau
    integrator = PRKIntegrator(2*unit.femtoseconds, PRKTableau(A, b, A_hat, b_hat), system=system)

:class:`PRKIntegrator` runs any PRK tableau pair, kick/drift splitting or catalogue method;
:class:`CustomSymplecticIntegrator` is the catalogue-method class that ``SymplecticIntegrator(...,
backend="custom")`` builds.  Both are plain ``openmm.CustomIntegrator`` s to OpenMM (Simulation, reporters,
checkpoints, XmlSerializer).  On top of the shared behaviour of :class:`~.base.IntegratorBase` they check,
at the first step, that the Context has the particle count of their ``system=`` (before anything is read
out of bounds) and, through the program's probe, that it has constraints only if the program keeps them;
and before every step that the program's signature (global 0) is still theirs, i.e. that no checkpoint of
another program was loaded.
"""
from __future__ import annotations

import math
import warnings
from dataclasses import replace

import openmm as mm
import openmm.unit as unit

from ..support.errors import InputError
from ..physics.velocity_rescaling import no_peculiar_motion
from ..systems.checks import warn_once
from ..systems.properties import masses, virtual_sites
from . import program, thermostat_program
from .backend import resolve_for_system
from .base import CheckpointMismatchError, ConvergenceWarning, IntegratorBase, SystemMismatchError
from .metadata import add_metadata, massless_particles, metadata
from .mismatch import mismatch_message
from .options import DEFAULT_MAX_ITERATIONS, DEFAULT_TOLERANCE, OPTIONS, IntegratorOptions, check_option_names
from .thermostat import thermostat_settings
from .projection import set_masses
from .symplectic import SymplecticIntegrator

__all__ = ["PRKIntegrator", "CustomSymplecticIntegrator", "TimeWarning", "VirtualSitesError"]


class TimeWarning(UserWarning):
    """OpenMM's CustomIntegrator keeps the Context's time on the old step size after setStepSize."""


class VirtualSitesError(InputError):
    """The CustomIntegrator backend was asked to run a System with virtual sites, which it cannot keep right."""


def _refuse_virtual_sites(where: str, system: mm.System) -> None:
    """VirtualSitesError for a System with virtual sites.  OpenMM's CustomIntegrator places them only at the end of a
    step on the Reference and CPU platforms (its ConstrainPositions leaves them where they are; only the Common
    platforms place them there), so every force evaluated inside a step sees each site where the previous step left
    it, one drift behind its molecule: 215 TIP4P-Ew waters with PME at 2 fs gain 238 kJ/mol in 1 ps of NVE where
    OpenMM's VerletIntegrator and the native backend stay within 8.  The integrator cannot know its platform before
    it runs, so the System is refused on every platform."""
    sites = virtual_sites(system)
    if not sites:
        return
    from .. import plugin

    if plugin.available():
        use = "Use the native backend, which places them after every drift: SymplecticIntegrator(..., backend='native')"
    else:
        use = (f"The native backend, which places them after every drift, is unavailable here "
               f"({plugin.unavailable_reason()}); to fix it, {plugin.fix_hint()}")
    raise VirtualSitesError(
        f"{where}: the System has {len(sites)} virtual site(s) (e.g. particle {sites[0]}), which the CustomIntegrator "
        f"backend cannot keep right: OpenMM's CustomIntegrator places them only at the end of each step on the "
        f"Reference and CPU platforms, so every force inside the step sees them one drift behind and the system heats "
        f"(215 TIP4P-Ew waters with PME at 2 fs: +238 kJ/mol in 1 ps of NVE, against 8 for VerletIntegrator). {use}; "
        f"or use a water model without virtual sites (TIP3P, SPC/E). Implicit and general PRK tableaux, which only the "
        f"CustomIntegrator backend runs, cannot run such a System.")


class PRKIntegrator(IntegratorBase, mm.CustomIntegrator):
    """A CustomIntegrator running any PRK tableau pair, kick/drift splitting or catalogue method.

    Parameters
    ----------
    stepSize : time Quantity or float (ps)
    tableau : PRKTableau, Splitting, catalogue Method, or a catalogue name
    system : openmm.System, optional
        The System the integrator will run.  It decides whether RATTLE constraint steps are compiled (without
        it they are, for splittings: correct for any System and cheap), is checked for anything that breaks
        conservation (one warning per kind), and is recorded: the first step refuses a Context with another
        particle count, or with constraints the program cannot keep.
    constraints : bool, optional
        Override the constraint decision (``True``/``False``); default: from ``system``.
    allow_nonsymplectic : bool
        Accept a tableau that fails Reich's condition (6) (e.g. rk4 as a reference).
    exact_momentum : bool
        Project the forces of every kick onto zero net force and torque, so that linear and angular momentum
        are conserved to double round-off even where forces are summed in single precision.  Needs
        ``system=`` (it is only right for an isolated System, which is checked, and it uses its masses).
    check_finite : bool
        Record the first step whose velocities are not finite; ``step`` raises SimulationBlowUpError.
    max_speed : float or speed Quantity, optional
        Also count velocities faster than this (nm/ps) as a blow-up (default: only NaN and infinity).
    groups : list of (force group, substeps), optional
        Multiple time stepping (r-RESPA), in the form of OpenMM's ``MTSIntegrator``: e.g. ``[(1, 1), (0, 2)]``
        kicks with group 1 once per step and runs two inner steps with group 0 in every drift
        (:mod:`openmm_symprk.methods.respa`; :func:`openmm_symprk.systems.forcegroups.split_forces` sets the groups).
    inner_method : the kick/drift method of the inner levels (default: the same as the outer one).
    tolerance, max_iterations : implicit methods only: fixed-point tolerance (nm) and iteration cap.
    temperature, collision_time, thermostat_interval, random_seed : the velocity-rescaling thermostat (NVT), see
        :func:`openmm_symprk.integrators.thermostat.thermostat_settings` and :mod:`.thermostat_program`;
        ``temperature`` needs ``system=``.  Without ``temperature`` the program is the NVE one, bit for bit.
    name : str, optional
        The method's name (default: its catalogue name, or the tableau's).

    The options are checked once, into one :class:`~.options.IntegratorOptions` (``integrator.options``).
    """

    backend = "custom"

    def __init__(self, stepSize, tableau, system: mm.System | None = None, name: str | None = None, *,
                 exact_momentum=False, check_finite=True, max_speed=None, groups=None, inner_method=None,
                 temperature=None, collision_time=None, thermostat_interval=None, random_seed=None,
                 thermostat_position=None, constraints=None, allow_nonsymplectic=False, tolerance=DEFAULT_TOLERANCE,
                 max_iterations=DEFAULT_MAX_ITERATIONS, **unknown):
        check_option_names(unknown, OPTIONS | {"name"}, type(self).__name__)
        options = IntegratorOptions.build(
            type(self).__name__, stepSize, system, exact_momentum=exact_momentum, check_finite=check_finite,
            max_speed=max_speed, groups=groups, inner_method=inner_method, constraints=constraints,
            allow_nonsymplectic=allow_nonsymplectic, tolerance=tolerance, max_iterations=max_iterations)
        self._remember_system(system)
        settings = thermostat_settings(system, temperature=temperature, collision_time=collision_time,
                                       thermostat_interval=thermostat_interval, random_seed=random_seed,
                                       thermostat_position=thermostat_position)
        self._compile(tableau, system, options, settings, name)

    def _compile(self, method, system, options: IntegratorOptions, settings=None, name: str | None = None):
        """Resolve ``method`` for ``system``, compile its program with ``options`` and the thermostat's ``settings``
        (None: NVE), and record its metadata."""
        if system is not None:
            _refuse_virtual_sites(type(self).__name__, system)
        r = resolve_for_system(type(self).__name__, method, system, options, name=name, thermostat=settings)
        r.check_symplectic(options.allow_nonsymplectic)
        has_sites = options.system.virtual_sites if options.system is not None else True
        mm.CustomIntegrator.__init__(self, options.step_size)
        self._set_program(r, options, program.compile_program(self, r, options, has_sites, settings))
        self._masses = masses(system) if options.exact_momentum else None
        self._massless = massless_particles(system) if system is not None else ()
        if settings is not None:
            self._set_thermostat(settings)
        self._reset_binding()
        add_metadata(self, metadata(type(self).__name__, method, r, options, settings, self._massless))

    def _set_program(self, r, options, info):
        """Record the resolved method, the options and the facts of the compiled program."""
        self.resolved = r
        self.options = options
        self.program_info = info

    def _forget_run_state(self, per_dof: bool = True):
        """Every variable at the value a freshly compiled program has, but the signature (global 0), the metadata and
        the thermostat's temperature and collision time (settings, which a copy keeps as they were last set).
        ``per_dof=False``: the global variables only (a bound integrator, whose per-DOF values the Context sized)."""
        options = self.options
        has_sites = options.system.virtual_sites if options.system is not None else True
        fresh = mm.CustomIntegrator(options.step_size)
        program.compile_program(fresh, self.resolved, options, has_sites, self.thermostat)
        kept = {program.SIGNATURE_VAR, thermostat_program.TEMPERATURE_VAR, thermostat_program.COLLISION_TIME_VAR}
        for i in range(fresh.getNumGlobalVariables()):
            name = fresh.getGlobalVariableName(i)
            if name not in kept:
                self.setGlobalVariableByName(name, fresh.getGlobalVariable(i))
        for i in range(fresh.getNumPerDofVariables() if per_dof else 0):
            self.setPerDofVariableByName(fresh.getPerDofVariableName(i), fresh.getPerDofVariable(i))

    # -- per-Context checks ----------------------------------------------------------------------------
    # OpenMM gives an integrator no way to its Context, so the checks below read only the integrator's own variables.
    # A Context made anew for it (Context.reinitialize(), which keeps the program's global variables) drops the
    # per-DOF values set while bound, the thermostat's mask and exact momentum's masses: their absence marks a run
    # the Context no longer holds, also in a State or checkpoint taken from such a Context before its first step.

    def _reset_binding(self):
        self._dt = self.getStepSize().value_in_unit(unit.picosecond)  # the step size (ps)
        self._checked_context = False
        self._n_particles = None  # the Context's, once checked
        self._checked_probe = False
        self._nonconverged_seen = 0
        self._warned_no_peculiar = False

    def _before_step(self):
        if not self._is_bound():
            return  # (the step raises OpenMM's "not bound to a context")
        if not self._checked_context:
            self._check_context()
        self._start_new_run_where_lost()
        stored = self.getGlobalVariable(0)
        if stored != self.program_info.signature:
            raise CheckpointMismatchError(mismatch_message(
                f"{type(self).__name__}({self.method_name})", self.resolved, self.options, self.thermostat, stored,
                self.program_info.signature, self._given_system()))
        if self.thermostat is not None:
            self._keep_thermostat_settings()

    def _start_new_run_where_lost(self):
        """Where the per-DOF values set while bound are missing (a reinitialized Context, or a State or checkpoint
        taken from one before its first step), the Context no longer holds the run its global variables describe:
        start a new one, as the native backend, whose kernel is made anew (heat bath, step counter, thermostat
        counters and first-step probe as a fresh integrator has them), and set those values again.  A step count
        set to 0 alone (``Simulation.currentStep = 0``), ``reinitialize(preserveState=True)``, a checkpoint and a
        State of a running Context keep the run.  (NVE programs without ``exact_momentum`` set nothing while bound:
        their step counter goes on.)"""
        if self._bound_values_intact():
            return
        if self.getGlobalVariableByName(program.PROBED_VAR) > 0.5:  # a run had begun
            self._forget_run_state(per_dof=False)
        self._set_bound_values()

    def _bound_values_intact(self) -> bool:
        """Whether the per-DOF values set while bound are in the Context: the thermostat's mask with its dof - 1 ones,
        exact momentum's masses not all zero (True for a program that sets none)."""
        if self.thermostat is not None:
            mask = self.getPerDofVariableByName(thermostat_program.MASK_VAR)
            if len(mask) != self._n_particles or sum(sum(vec) for vec in mask) != self.thermostat.dof - 1:
                return False
        if self._masses is not None:
            from .projection import MASS_VAR

            if not any(vec[0] for vec in self.getPerDofVariableByName(MASS_VAR)):
                return False
        return True

    def _set_bound_values(self):
        """Set the per-DOF values a bound program needs: exact momentum's masses, the thermostat's mask."""
        if self._masses is not None:
            set_masses(self, self._masses)
        if self.thermostat is not None:
            self.setPerDofVariableByName(thermostat_program.MASK_VAR,
                                         thermostat_program.mask_values(self._has_mass(), self.thermostat.dof))

    def _has_mass(self) -> list:
        """1 for each particle with mass, 0 for the massless ones (of ``system=``, or of the metadata of an integrator
        read from XML)."""
        massless = set(self._massless)
        return [0.0 if i in massless else 1.0 for i in range(self._n_particles)]

    def _is_bound(self) -> bool:
        """Whether a Context holds the integrator now (OpenMM's step(0) does nothing else than check it)."""
        try:
            mm.CustomIntegrator.step(self, 0)
        except mm.OpenMMException:
            return False
        return True

    def _sync_run_state(self):
        """Between steps, what the native backend reports at once: where the Context no longer holds the run (see
        :meth:`_start_new_run_where_lost`) the values of a new run (else they would change only at the next step)."""
        if (self.thermostat is not None or self._masses is not None) and self._is_bound():
            if not self._checked_context:
                self._check_context()
            self._start_new_run_where_lost()

    def _keep_thermostat_settings(self):
        """Give the program the integrator's current temperature and collision time if a checkpoint (or a State's
        integrator parameters) brought back the ones it was saved with: as OpenMM's own thermostatted integrators,
        whose temperature is the integrator's and not the Context's, and as the native backend."""
        get = self.getGlobalVariableByName
        held = (get(thermostat_program.TEMPERATURE_VAR), get(thermostat_program.COLLISION_TIME_VAR))
        # (a single-precision platform holds the globals as floats: compare to that precision)
        if not all(math.isclose(a, b, rel_tol=1e-6) for a, b in
                   zip(held, (self.thermostat.temperature, self.thermostat.collision_time))):
            self._apply_thermostat(self.thermostat)

    def _check_context(self):
        """First step on a Context: its particle count against ``system=`` (read from a per-DOF variable the
        Context sized)."""
        n = len(self.getPerDofVariableByName(program.PROBE_PER_DOF))
        expected = self.options.system.n_particles if self.options.system is not None else None
        if expected is not None and n != expected:
            raise SystemMismatchError(
                f"{type(self).__name__}({self.method_name}) was compiled for a System of {expected} particles, but "
                f"its Context's System has {n}: create the integrator with system= the System you simulate")
        self._n_particles = n
        self._checked_context = True

    # -- the thermostat (see IntegratorBase for the accessors) ---------------------------------------------
    def program_thermostat_settings(self, settings):
        """``settings`` with the temperature, collision time and seed this program holds (an integrator read from XML:
        as they were last set, where its metadata has them as created)."""
        get = self.getGlobalVariableByName
        return replace(settings, temperature=get(thermostat_program.TEMPERATURE_VAR),
                       collision_time=get(thermostat_program.COLLISION_TIME_VAR),
                       seed=int(mm.CustomIntegrator.getRandomNumberSeed(self)))

    def _apply_thermostat(self, settings):
        """The program's variables (temperature, collision time) and OpenMM's seed for the next Context.  (A checkpoint
        or a State may bring back the program's older values: :meth:`_keep_thermostat_settings` overrules them before
        the next step, as the native backend, whose plugin is not in the checkpoint, does.)"""
        self.setGlobalVariableByName(thermostat_program.TEMPERATURE_VAR, settings.temperature)
        self.setGlobalVariableByName(thermostat_program.COLLISION_TIME_VAR, settings.collision_time)
        mm.CustomIntegrator.setRandomNumberSeed(self, int(settings.seed))

    def _heat_bath_energy(self) -> float:
        return self.getGlobalVariableByName(thermostat_program.HEAT_BATH_VAR)

    def _still(self) -> bool:
        get = self.getGlobalVariableByName
        return no_peculiar_motion(get(thermostat_program.KINETIC_VAR), get(thermostat_program.TOTAL_KINETIC_VAR))

    def _skipped_thermostat_events(self) -> int:
        return int(self.getGlobalVariableByName(thermostat_program.SKIPPED_VAR))

    def _thermostat_kinetic_energy(self) -> float:
        return thermostat_program.event_kinetic_energy(self)

    def _thermostat_peculiar_kinetic_energy(self) -> float:
        return self.getGlobalVariableByName(thermostat_program.NEW_KINETIC_VAR)

    def _after_step(self):
        if self.thermostat is not None and self.getGlobalVariableByName(thermostat_program.LOST_MASK_VAR):
            # the events found the mask without its dof - 1 ones and did nothing (alpha = 1): per-DOF values were
            # replaced during the call (the checks before it found the mask in place); fill it again
            self.setGlobalVariableByName(thermostat_program.LOST_MASK_VAR, 0.0)
            self._set_bound_values()
            warnings.warn(f"{type(self).__name__}({self.method_name}): the thermostat's per-DOF mask was lost during "
                          f"this step() call, so its steps ran without the thermostat; it is restored for the next "
                          f"steps.", RuntimeWarning, stacklevel=3)
        if not self._checked_probe:
            self._checked_probe = True
            if self.getGlobalVariableByName(program.PROBE_CONSTRAINTS_VAR) > 0 and not self.program_info.rattle:
                what = ("a general PRK tableau, which cannot keep constraints" if not self.resolved.is_splitting
                        else "a System without constraints (system=, or constraints=False)")
                raise SystemMismatchError(
                    f"{type(self).__name__}({self.method_name}) was compiled for {what}, but its Context's System "
                    f"has constraints: this first step did not keep them. Create the integrator with system= the "
                    f"System you simulate (a kick/drift method then compiles RATTLE steps).")
        if self.resolved.form == "implicit":
            n = int(self.getGlobalVariableByName(program.NONCONV_VAR))
            if n > self._nonconverged_seen:
                warnings.warn(
                    f"{self.method_name}: the implicit stage iteration reached its cap on {n - self._nonconverged_seen} "
                    f"step(s) (total {n}); results are less accurate there. Reduce the step size or raise "
                    f"max_iterations/tolerance.", ConvergenceWarning, stacklevel=3)
                self._nonconverged_seen = n

    # -- backend hooks -----------------------------------------------------------------------------------
    def _blowup_step(self) -> int:
        return int(self.getGlobalVariableByName(program.BAD_VAR))

    def _clear_blowup(self):
        self.setGlobalVariableByName(program.BAD_VAR, 0.0)

    def _raw_steps_taken(self) -> int:
        return int(self.getGlobalVariableByName(program.STEP_VAR))

    # -- the step size --------------------------------------------------------------------------------------
    def setStepSize(self, size):
        """Set the step size (checked).  On a bound integrator it warns once: OpenMM's CustomIntegrator on the Reference
        and CPU platforms goes on advancing the Context's time by the step size the Context was created with (the
        steps themselves take the new one), and the integrator cannot reach its Context to set the time."""
        result = super().setStepSize(size)
        dt = self.getStepSize().value_in_unit(unit.picosecond)
        if dt != self._dt and self._is_bound():
            warn_once("custom-setstepsize-time",
                      f"{type(self).__name__}({self.method_name}): the step size changed from {self._dt:g} to {dt:g} ps "
                      f"while the integrator runs a Context; on the Reference and CPU platforms OpenMM's "
                      f"CustomIntegrator goes on advancing the Context's time by the step size the Context was created "
                      f"with (the steps take the new one). Call context.reinitialize(preserveState=True) after "
                      f"setStepSize, or use the native backend, whose time follows the step size.", TimeWarning)
        self._dt = dt
        return result

    def describe(self) -> str:
        info, r = self.program_info, self.resolved
        size = f"{sum(s.is_kick_or_drift for s in r.substeps)} kicks and drifts" if r.is_splitting else f"{r.stages} stages"
        lines = [f"{type(self).__name__}: {self.method_name}, step {self.getStepSize()}, CustomIntegrator backend",
                 f"  program: {r.form}, {size}, constraints={'RATTLE' if info.rattle else 'none'}, force evaluations "
                 f"per step: {r.force_evals}, exact momentum: {self.options.exact_momentum}",
                 f"  {r.tableau.summary()}" if r.tableau is not None else "  multiple time stepping"]
        lines += [f"  {n}" for n in info.notes]
        if r.is_mts:
            lines.append("  " + r.describe_levels())
        if self.thermostat is not None:
            lines.append("  " + self.thermostat.describe(r.thermostat_position, outer=r.is_mts))
        return "\n".join(lines)


class CustomSymplecticIntegrator(SymplecticIntegrator, PRKIntegrator, backend="custom"):
    """A catalogue method on the CustomIntegrator backend: what ``SymplecticIntegrator(..., backend="custom")``
    builds, and what ``backend="auto"`` builds for implicit and general tableaux.  Parameters: those of
    :class:`~openmm_symprk.integrators.symplectic.SymplecticIntegrator` and :class:`PRKIntegrator`."""

    def __init__(self, stepSize, method="verlet", system: mm.System | None = None, backend: str = "custom", **options):
        self._check_backend(backend)
        PRKIntegrator.__init__(self, stepSize, method, system, **options)
