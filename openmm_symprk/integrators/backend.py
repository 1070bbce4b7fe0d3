"""Which backend runs a catalogue method: the native plugin or the CustomIntegrator program.

An integrator is built before the Context, so the choice cannot wait for the platform.  ``backend="auto"``
therefore takes the native plugin only when it has a kernel for *every* platform OpenMM loaded in this
process (whichever one a Simulation then picks, it runs); otherwise it takes the CustomIntegrator program,
which runs everywhere, and warns once, naming the platforms without a kernel, why, and the command that
fixes it.  ``symprk info`` lists the same per platform.

The options both backends take are checked here once (:func:`check_option_names`, :func:`prepare`): each
backend's constructor calls :func:`prepare`, which validates the step size and the options, checks the System
and resolves the method (:func:`openmm_symprk.methods.resolved.resolve`) with the System's constraint facts.
"""
from __future__ import annotations

import difflib
from dataclasses import dataclass


from .. import plugin
from ..methods.resolved import ConstraintSupportError, ResolvedMethod, resolve
from ..systems.checks import check_system_type, validate_system, warn_once
from ..systems.forcegroups import check_groups
from ..systems.properties import SystemSignature, signature
from .base import check_max_speed, step_size_in_ps
from .thermostat import THERMOSTAT_OPTIONS, ThermostatSettings, thermostat_settings

__all__ = ["BACKENDS", "NATIVE_OPTIONS", "CUSTOM_OPTIONS", "OPTIONS", "choose_backend", "check_option_names",
           "prepare", "Prepared", "BackendWarning", "NativeMethodError", "NativeUnavailableError"]

BACKENDS = ("auto", "native", "custom")
#: Options of SymplecticIntegrator that both backends take (the native backend takes these only).
NATIVE_OPTIONS = frozenset({"exact_momentum", "check_finite", "max_speed", "groups", "inner_method",
                            *THERMOSTAT_OPTIONS})
#: Options only the CustomIntegrator backend takes.
CUSTOM_OPTIONS = frozenset({"allow_nonsymplectic", "constraints", "tolerance", "max_iterations"})
#: Every option of SymplecticIntegrator.
OPTIONS = NATIVE_OPTIONS | CUSTOM_OPTIONS
NativeUnavailableError = plugin.NativeUnavailableError


class BackendWarning(UserWarning):
    """backend="auto" could not use the native plugin (the message says why and how to fix it)."""


class NativeMethodError(ValueError):
    """The method cannot run on the native backend (only kick/drift splittings and compositions can)."""


def check_option_names(given, accepted, where: str) -> None:
    """TypeError naming every option of ``given`` that is not in ``accepted``, with close names (difflib), as
    method names get; a bare Python TypeError would say neither."""
    accepted = sorted(accepted)
    bad = [k for k in given if k not in accepted]
    if not bad:
        return
    parts = []
    for k in bad:
        close = difflib.get_close_matches(str(k), accepted, n=3, cutoff=0.6)
        parts.append(f"{k!r}" + (f" (did you mean {', '.join(map(repr, close))}?)" if close else ""))
    raise TypeError(f"{where} got {'an unknown option' if len(bad) == 1 else 'unknown options'} {', '.join(parts)}; "
                    f"it accepts {', '.join(accepted)}")


@dataclass(frozen=True)
class Prepared:
    """What :func:`prepare` checked and derived, for a backend's constructor."""

    dt: float  # step size in ps
    method: ResolvedMethod
    exact_momentum: bool
    check_finite: bool
    max_speed: float  # nm/ps, 0: only NaN and infinity
    system: SystemSignature | None  # the facts of system=, None without one
    thermostat: ThermostatSettings | None = None  # None: no thermostat (NVE)


def prepare(where: str, stepSize, method, system=None, *, exact_momentum=False, check_finite=True, max_speed=None,
            groups=None, inner_method=None, constraints=None, name=None, splittings_only: str | None = None,
            skip_checks=(), temperature=None, collision_time=None, thermostat_interval=None,
            random_seed=None) -> Prepared:
    """The checks and derivations both backends share, in one place.

    Validates the step size and options, refuses ``exact_momentum`` without ``system``, resolves the method with
    the System's constraint facts (``constraints`` overrides them; without a System kick/drift methods keep
    RATTLE steps), checks the System (one warning per kind of conservation issue, less ``skip_checks``) and the
    force groups of multiple time stepping against it.  The thermostat options (``temperature``,
    ``collision_time``, ``thermostat_interval``, ``random_seed``) are checked by
    :func:`.thermostat.thermostat_settings` and give ``Prepared.thermostat``.  ``splittings_only``: the backend runs kick/drift
    methods only; a general PRK pair raises NativeMethodError with this hint."""
    dt = step_size_in_ps(stepSize)
    max_speed = check_max_speed(max_speed)
    if exact_momentum and system is None:
        raise ValueError("exact_momentum=True needs system= (the System the integrator will run): the projection "
                         "is only right for an isolated System, which is checked, and it uses the System's masses")
    if system is not None:
        check_system_type(system)
    thermostat = thermostat_settings(system, temperature, collision_time, thermostat_interval, random_seed)
    facts = signature(system) if system is not None else None
    if constraints is None and facts is not None:
        constraints = facts.constraints
    try:
        resolved = resolve(method, constraints=constraints, groups=groups, inner_method=inner_method, name=name)
    except ConstraintSupportError:
        if splittings_only is None:
            raise
        resolved = resolve(method, name=name)
    if splittings_only is not None and not resolved.is_splitting:
        raise NativeMethodError(
            f"method {resolved.name!r} is a general ({resolved.family or resolved.kind}) PRK tableau; {splittings_only}")
    if system is not None:
        validate_system(system, f"{where}({resolved.name})", exact_momentum, skip=skip_checks)
        if resolved.groups is not None:
            check_groups(system, resolved.groups)
    return Prepared(dt, resolved, bool(exact_momentum), bool(check_finite), max_speed, facts, thermostat)


def choose_backend(method, backend: str = "auto", options=None) -> str:
    """"native" or "custom" for a catalogue method (see the module docstring)."""
    if backend not in BACKENDS:
        raise ValueError(f"backend must be one of {', '.join(map(repr, BACKENDS))}, got {backend!r}")
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
                f"of the {m.family or m.kind} family. Use backend='custom' (or 'auto').")
        if extra:
            raise ValueError(f"backend='native' does not take the option(s) {', '.join(extra)}; it accepts "
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
