"""Which backend runs a catalogue method: the native plugin or the CustomIntegrator program.

An integrator is built before the Context, so the choice cannot wait for the platform.  ``backend="auto"``
therefore takes the native plugin only when it has a kernel for *every* platform OpenMM loaded in this
process (whichever one a Simulation then picks, it runs); otherwise it takes the CustomIntegrator program,
which runs everywhere, and warns once, naming the platforms without a kernel, why, and the command that
fixes it.  ``symprk info`` lists the same per platform.

The options are checked once, into one :class:`~.options.IntegratorOptions`; each backend's constructor then calls
:func:`resolve_for_system`, which resolves the method (:func:`openmm_symprk.methods.resolved.resolve`) with the
System's constraint facts and checks the System against it (warning about what breaks the conservation the run asked
for: an NVT run's periodic box and CMMotionRemover are not warned about), and warns once where the step is beyond what
the method was measured to run on a System of its kind (:mod:`openmm_symprk.systems.step_limits`), and where
``thermostat_position="middle"`` was asked for a method whose middle samples worse than its ends
(:func:`openmm_symprk.methods.resolved.placement_advice`).
"""
from __future__ import annotations

from .. import plugin
from ..methods.resolved import ConstraintSupportError, ResolvedMethod, placement_advice, resolve
from ..systems.checks import validate_system, warn_once
from ..systems.forcegroups import check_groups
from ..systems.step_limits import warn_step_limit
from .options import NATIVE_OPTIONS, OPTIONS, IntegratorOptions, check_option_names
from ..support.errors import InputError

__all__ = ["BACKENDS", "choose_backend", "resolve_for_system", "BackendWarning", "PlacementWarning", "NativeMethodError",
           "NativeUnavailableError"]

BACKENDS = ("auto", "native", "custom")
NativeUnavailableError = plugin.NativeUnavailableError


class BackendWarning(UserWarning):
    """backend="auto" could not use the native plugin (the message says why and how to fix it)."""


class PlacementWarning(UserWarning):
    """``thermostat_position="middle"`` asked for a method whose configurations it samples further from canonical
    than the ends (every method but Verlet; the message says where the middle falls and what it costs)."""


class NativeMethodError(InputError):
    """The method cannot run on the native backend (only kick/drift splittings and compositions can)."""


def resolve_for_system(where: str, method, system, options: IntegratorOptions, name: str | None = None,
                       splittings_only: str | None = None, skip_checks=(), thermostat=None) -> ResolvedMethod:
    """``method`` resolved as it will run on ``system`` (the System of the checked ``options``), the System checked.

    The constraint facts come from ``options.constraints``, else from the System (without one kick/drift methods
    keep RATTLE steps); the System is checked for anything that breaks conservation (one warning per kind, less
    ``skip_checks``) and against the force groups of multiple time stepping.  With a ``thermostat`` (its
    :class:`~.thermostat.ThermostatSettings`), the method is resolved with the placement asked for
    (``thermostat.position``: the events become THERMOSTAT sub-steps).  ``name`` overrides the method's name.
    ``splittings_only``: the backend runs kick/drift methods only; a general PRK pair raises NativeMethodError with
    this hint."""
    facts = options.system
    constraints = options.constraints
    if constraints is None and facts is not None:
        constraints = facts.constraints
    position = thermostat.position if thermostat is not None else None
    try:
        resolved = resolve(method, constraints=constraints, groups=options.groups, inner_method=options.inner_method,
                           name=name, thermostat_position=position)
    except ConstraintSupportError:
        if splittings_only is None:
            raise
        resolved = resolve(method, name=name, thermostat_position=position)
    if splittings_only is not None and not resolved.is_splitting:
        raise NativeMethodError(
            f"method {resolved.name!r} is a general ({resolved.family or resolved.form}) PRK tableau; "
            f"{splittings_only}")
    advice = placement_advice(resolved, position)
    if advice is not None:
        warn_once(f"placement-middle-{resolved.name}", f"{where}({resolved.name}): {advice}", PlacementWarning)
    if system is not None:
        validate_system(system, f"{where}({resolved.name})", options.exact_momentum, skip=skip_checks,
                        thermostat=thermostat is not None)
        if resolved.entry is not None and not resolved.is_mts:
            warn_step_limit(system, resolved.entry.name, options.step_size * 1000.0, f"{where}({resolved.name})")
        if resolved.groups is not None:
            check_groups(system, resolved.groups)
    return resolved


def choose_backend(method, backend: str = "auto", options=None) -> str:
    """"native" or "custom" for a catalogue method (see the module docstring)."""
    if backend not in BACKENDS:
        raise InputError(f"backend must be one of {', '.join(map(repr, BACKENDS))}, got {backend!r}")
    check_option_names(options or {}, OPTIONS, "SymplecticIntegrator")
    if backend == "custom":
        return "custom"
    m = resolve(method)
    extra = sorted(set(options or {}) - NATIVE_OPTIONS)
    if backend == "native":
        if not plugin.available():
            raise NativeUnavailableError(f"backend='native' was asked for, but the native backend is unavailable: "
                                         f"{plugin.unavailable_reason()}. To fix it, {plugin.fix_hint()}.")
        if not m.is_splitting:
            raise NativeMethodError(
                f"backend='native' runs kick/drift splittings and compositions only; {m.name!r} is a PRK tableau "
                f"of the {m.family or m.form} family. Use backend='custom' (or 'auto').")
        if extra:
            raise InputError(f"backend='native' does not take the option(s) {', '.join(extra)}; it accepts "
                             f"{', '.join(sorted(NATIVE_OPTIONS))}. Use backend='custom'.")
        return "native"
    if not m.is_splitting or extra:
        return "custom"  # by design: general tableaux and CustomIntegrator-only options
    if not plugin.available():
        warn_once("backend-native-unavailable",
                  f"openmm_symprk: the native backend is unavailable ({plugin.unavailable_reason()}), so "
                  f"SymplecticIntegrator uses the CustomIntegrator program (same trajectories, about 1.2-1.4x "
                  f"the time per step). To fix it, {plugin.fix_hint()}.", BackendWarning)
        return "custom"
    missing = {p: how for p, how in plugin.details().items() if how != "native"}
    if missing:
        warn_once("backend-native-platforms",
                  f"openmm_symprk: the native plugin has no kernel for the platform(s) "
                  f"{', '.join(missing)} ({'; '.join(f'{p}: {why}' for p, why in missing.items())}), so "
                  f"SymplecticIntegrator(backend='auto') uses the CustomIntegrator program, which runs on every "
                  f"platform. backend='native' runs on {', '.join(plugin.platforms())}; `symprk info` lists them.",
                  BackendWarning)
        return "custom"
    return "native"
