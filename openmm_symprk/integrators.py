"""The drop-in integrators: openmm.CustomIntegrator subclasses built by :mod:`openmm_symprk.program`.

    from openmm_symprk import SymplecticIntegrator
    integrator = SymplecticIntegrator(2*unit.femtoseconds, method="yoshida-4", system=system)

Both classes are plain CustomIntegrators to OpenMM, so Simulation, reporters, checkpoints and
XmlSerializer work.  Deserialising the XML gives a plain ``openmm.CustomIntegrator`` with the same
program (the Python conveniences -- method name, blow-up check on ``step`` -- are not in the XML).
"""
from __future__ import annotations

import math
import warnings

import openmm as mm
import openmm.unit as unit

from . import program
from .catalogue import Method, get_method
from .splitting import Splitting
from .systemcheck import has_constraints, validate_system
from .tableau import PRKTableau, TableauError


class SimulationBlowUpError(RuntimeError):
    """The velocities stopped being finite (the step size is beyond the method's stability limit)."""


class ConvergenceWarning(RuntimeWarning):
    """An implicit method's fixed-point iteration hit its iteration cap on some steps."""


def step_size_in_ps(step_size) -> float:
    """Validate a step size: a positive time Quantity, or a positive number taken as picoseconds."""
    if unit.is_quantity(step_size):
        if not step_size.unit.is_compatible(unit.picoseconds):
            raise TypeError(f"step size {step_size} is not a time: give it in time units, e.g. "
                            f"2*unit.femtoseconds (a plain number is taken as picoseconds)")
        value = step_size.value_in_unit(unit.picoseconds)
    else:
        value = step_size
    try:
        value = float(value)
    except (TypeError, ValueError):
        raise TypeError(f"step size {step_size!r} is not a time: give e.g. 2*unit.femtoseconds "
                        f"or a number of picoseconds") from None
    if not math.isfinite(value) or value <= 0:
        raise ValueError(f"step size must be positive and finite, got {step_size} "
                         f"(e.g. 2*unit.femtoseconds or 0.002 ps)")
    return value


class PRKIntegrator(mm.CustomIntegrator):
    """A CustomIntegrator running any PRK tableau pair or kick/drift splitting.

    Parameters
    ----------
    stepSize : time Quantity or float (ps)
    tableau : PRKTableau, Splitting, or catalogue Method
    system : openmm.System, optional
        The system the integrator will run.  It decides whether RATTLE constraint steps are compiled
        (a system with constraints needs them; without ``system`` they are included, which is correct
        for any system and costs one constraint solve per drift) and is checked for anything that breaks
        conservation (CMMotionRemover, periodic box, thermostats: one warning each).
    constraints : bool, optional
        Override the constraint decision (``True``/``False``); default: from ``system``.
    allow_nonsymplectic : bool
        Accept a tableau that fails Reich's condition (6) (e.g. rk4 as a reference).
    exact_momentum : bool
        Project the forces of every kick onto zero net force and torque, so that linear and angular
        momentum are conserved to double round-off even where forces are summed in single precision.
    check_finite : bool
        Record the first step whose velocities are not finite; ``step`` raises SimulationBlowUpError.
    tolerance, max_iterations : implicit methods only: fixed-point tolerance (nm) and iteration cap.
    """

    def __init__(self, stepSize, tableau, system: mm.System | None = None, constraints: bool | None = None,
                 allow_nonsymplectic: bool = False, exact_momentum: bool = False, check_finite: bool = True,
                 tolerance: float = 1e-12, max_iterations: int = 60, name: str | None = None):
        dt = step_size_in_ps(stepSize)
        method = self._resolve(tableau)
        tab = method.tableau() if isinstance(method, Method) else (
            PRKTableau.from_splitting(method, name=name) if isinstance(method, Splitting) else method)
        self.method_name = name or getattr(method, "name", None) or "user tableau"
        tab.check_symplectic(allow_nonsymplectic)
        if tolerance <= 0 or not math.isfinite(tolerance):
            raise ValueError(f"tolerance must be a positive number of nm, got {tolerance!r}")
        if int(max_iterations) < 1:
            raise ValueError(f"max_iterations must be at least 1, got {max_iterations!r}")
        if system is not None:
            validate_system(system, f"{type(self).__name__}({self.method_name})", exact_momentum)
        if constraints is None:
            if system is not None:
                constraints = has_constraints(system)
            elif isinstance(method, Splitting) or (isinstance(method, Method) and method.is_splitting) or (
                    isinstance(method, PRKTableau) and _is_splitting(method)):
                constraints = True  # RATTLE steps are harmless (and cheap) on a system without constraints
            else:
                constraints = False
                warnings.warn(
                    f"{self.method_name} is a general PRK tableau, which cannot keep constraints, and no "
                    f"system= was given to check against: it will ignore any constraints of the system it runs. "
                    f"Pass system= to have this checked.", UserWarning, stacklevel=3)
        super().__init__(dt)
        self.tableau = tab
        try:
            self.program_info = program.compile_program(
                self, method, bool(constraints), exact_momentum=exact_momentum, check_finite=check_finite,
                tolerance=tolerance, max_iterations=int(max_iterations), system=system)
        except program.ConstraintSupportError as exc:
            raise program.ConstraintSupportError(str(exc).replace("user tableau", self.method_name)) from None
        self.check_finite = check_finite
        self._nonconverged_seen = 0

    @staticmethod
    def _resolve(tableau):
        if isinstance(tableau, (PRKTableau, Splitting, Method)):
            return tableau
        if isinstance(tableau, str):
            return get_method(tableau)
        raise TypeError(f"expected a PRKTableau, Splitting or catalogue method, got {tableau!r}")

    # -- OpenMM overrides ---------------------------------------------------------------
    def setStepSize(self, size):
        return super().setStepSize(step_size_in_ps(size))

    def step(self, steps):
        """Advance ``steps`` steps; raise SimulationBlowUpError if the simulation blew up."""
        try:
            result = super().step(steps)
        except mm.OpenMMException as exc:  # CPU/CUDA check coordinates themselves
            if "NaN" not in str(exc):
                raise
            raise self._blow_up(int(self.getGlobalVariableByName(program.STEP_VAR)) + 1, "positions became NaN") from exc
        if self.check_finite:
            bad = self.getGlobalVariableByName(program.BAD_VAR)
            if bad:
                raise self._blow_up(int(bad), "velocities became NaN, infinite or faster than 1e5 nm/ps")
        if self.program_info.kind == "implicit":
            n = int(self.getGlobalVariableByName(program.NONCONV_VAR))
            if n > self._nonconverged_seen:
                warnings.warn(
                    f"{self.method_name}: the implicit stage iteration reached its cap on {n - self._nonconverged_seen} "
                    f"step(s) (total {n}); results are less accurate there. Reduce the step size or raise "
                    f"max_iterations/tolerance.", ConvergenceWarning, stacklevel=2)
                self._nonconverged_seen = n
        return result

    def _blow_up(self, step: int, what: str) -> SimulationBlowUpError:
        return SimulationBlowUpError(
            f"the simulation blew up at integrator step {step} with method {self.method_name!r} at step size "
            f"{self.getStepSize()}: {what}. Reduce the step size (largest stable "
            f"h*omega for this method: {self._stability()}), or minimize the energy first. The Context "
            f"still holds the non-finite state; reload a checkpoint or positions saved before this call.")

    def _stability(self):
        try:
            st = get_method(self.method_name).stability
        except Exception:
            return "unknown"
        return "unbounded" if st is None or math.isinf(st) else f"{st:.4f}"

    # -- conveniences -------------------------------------------------------------------
    @property
    def steps_taken(self) -> int:
        return int(self.getGlobalVariableByName(program.STEP_VAR))

    def describe(self) -> str:
        info = self.program_info
        lines = [f"{type(self).__name__}: {self.method_name}, step {self.getStepSize()}",
                 f"  program: {info.kind}, {info.stages} {'kicks and drifts' if info.kind == 'splitting' else 'stages'}, constraints={'RATTLE' if info.constraints else 'none'}, "
                 f"force evaluations per step: {info.force_evals}, exact momentum: {info.exact_momentum}",
                 f"  {self.tableau.summary()}"]
        lines += [f"  {n}" for n in info.notes]
        return "\n".join(lines)


def _is_splitting(tab: PRKTableau) -> bool:
    try:
        tab.to_splitting()
        return True
    except TableauError:
        return False


BACKENDS = ("auto", "native", "custom")


def _platform_names() -> list:
    return [mm.Platform.getPlatform(i).getName() for i in range(mm.Platform.getNumPlatforms())]

#: options of SymplecticIntegrator that the native backend supports
_NATIVE_OPTIONS = {"exact_momentum", "check_finite"}


def choose_backend(method, backend: str = "auto", options=None) -> str:
    """'native' or 'custom' for a catalogue method (see :class:`SymplecticIntegrator`)."""
    if backend not in BACKENDS:
        raise ValueError(f"backend must be one of {', '.join(map(repr, BACKENDS))}, got {backend!r}")
    if backend == "custom":
        return "custom"
    from . import native

    m = get_method(method)
    extra = sorted(set(options or {}) - _NATIVE_OPTIONS)
    if backend == "native":
        if not native.native_available():
            raise native.NativeUnavailableError(f"backend='native' was asked for, but the native backend is "
                                                f"unavailable: {native.unavailable_reason()}")
        if not m.is_splitting:
            raise native.NativeMethodError(
                f"backend='native' runs kick/drift splittings and compositions only; {m.name!r} is a "
                f"PRK tableau of the {m.family} family. Use backend='custom' (or 'auto').")
        if extra:
            raise ValueError(f"backend='native' does not take the option(s) {', '.join(extra)}; "
                             f"it accepts {', '.join(sorted(_NATIVE_OPTIONS))}. Use backend='custom'.")
        return "native"
    # auto: native only where it can run everything this installation may use it on
    usable = (m.is_splitting and not extra and native.native_available()
              and set(_platform_names()) <= set(native.native_platforms()))
    return "native" if usable else "custom"


class SymplecticIntegrator(PRKIntegrator):
    """A catalogue method by name (``openmm_symprk.methods``), e.g. "verlet", "yoshida-4", "kahan-li-8".

    See :class:`PRKIntegrator` for the options.  Names are case-insensitive and accept aliases
    (velocity-verlet, forest-ruth, ...); an unknown name raises UnknownMethodError with close names.

    ``backend``: "auto" (default) returns the native plugin integrator
    (:class:`openmm_symprk.native.NativeSymplecticIntegrator`, no CustomIntegrator overhead) when it is
    built, the method is a kick/drift splitting or composition, only ``exact_momentum``/``check_finite``
    options are given, and the plugin has kernels for every platform of this OpenMM installation;
    otherwise this CustomIntegrator.  "native" insists on the plugin (a clear error if it cannot be
    used), "custom" on the CustomIntegrator program.  ``symprk info`` shows what each platform gets."""

    def __new__(cls, stepSize=None, method: str = "verlet", system: mm.System | None = None, backend: str = "auto",
                **options):
        if choose_backend(method, backend, options) == "native":
            from .native import NativeSymplecticIntegrator

            ig = NativeSymplecticIntegrator(stepSize, method, system=system, **options)
            ig.backend = "native"
            ig.program_info = program.ProgramInfo(
                "splitting", system is None or has_constraints(system), ig.splitting.force_evaluations(),
                len(ig.splitting), bool(options.get("exact_momentum", False)), ["native SymPRKIntegrator plugin"])
            return ig
        return super().__new__(cls)

    def __init__(self, stepSize, method: str = "verlet", system: mm.System | None = None, backend: str = "auto",
                 **options):
        m = get_method(method)
        super().__init__(stepSize, m, system=system, name=m.name, **options)
        self.method = m
        self.backend = "custom"
