"""Which backend runs a catalogue method: the native plugin or the CustomIntegrator program.

An integrator is built before the Context, so the choice cannot wait for the platform.  ``backend="auto"``
therefore takes the native plugin only when it has a kernel for *every* platform OpenMM loaded in this
process (whichever one a Simulation then picks, it runs); otherwise it takes the CustomIntegrator program,
which runs everywhere, and warns once, naming the platforms without a kernel, why, and the command that
fixes it.  ``symprk info`` lists the same per platform.
"""
from __future__ import annotations

from .. import plugin
from ..methods.catalogue import get_method
from ..systems.checks import warn_once

__all__ = ["BACKENDS", "NATIVE_OPTIONS", "choose_backend", "BackendWarning", "NativeMethodError",
           "NativeUnavailableError"]

BACKENDS = ("auto", "native", "custom")
#: Options of SymplecticIntegrator that the native backend takes.
NATIVE_OPTIONS = frozenset({"exact_momentum", "check_finite", "max_speed", "groups", "inner_method"})
NativeUnavailableError = plugin.NativeUnavailableError


class BackendWarning(UserWarning):
    """backend="auto" could not use the native plugin (the message says why and how to fix it)."""


class NativeMethodError(ValueError):
    """The method cannot run on the native backend (only kick/drift splittings and compositions can)."""


def choose_backend(method, backend: str = "auto", options=None) -> str:
    """"native" or "custom" for a catalogue method (see the module docstring)."""
    if backend not in BACKENDS:
        raise ValueError(f"backend must be one of {', '.join(map(repr, BACKENDS))}, got {backend!r}")
    if backend == "custom":
        return "custom"
    m = get_method(method)
    extra = sorted(set(options or {}) - NATIVE_OPTIONS)
    if backend == "native":
        if not plugin.available():
            raise NativeUnavailableError(f"backend='native' was asked for, but the native backend is unavailable: "
                                         f"{plugin.unavailable_reason()}. To fix it, {plugin.fix_hint()}.")
        if not m.is_splitting:
            raise NativeMethodError(
                f"backend='native' runs kick/drift splittings and compositions only; {m.name!r} is a PRK tableau "
                f"of the {m.family} family. Use backend='custom' (or 'auto').")
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
