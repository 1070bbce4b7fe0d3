"""The native backend: the SymPRKIntegrator OpenMM plugin built from ``platforms/`` by ``pip install .``.

    from openmm_symprk.native import native_available, NativeSymplecticIntegrator
    if native_available():
        integrator = NativeSymplecticIntegrator(2*unit.femtoseconds, "yoshida-4", system=system)

The plugin runs the same kick/drift program as :class:`openmm_symprk.SymplecticIntegrator` (the
CustomIntegrator compiled by :mod:`openmm_symprk.program`): on Reference both give the same trajectory
bit for bit, without CustomIntegrator's per-degree-of-freedom interpreter.  Kernels: Reference and CPU
(one kernel; CPU's threaded SETTLE and the platform's thread pool), OpenCL (Common compute source), and
CUDA when built on a CUDA machine (``SYMPRK_BUILD_CUDA=1``).

When the plugin was not built (no compiler, no SWIG, build failure: ``pip install .`` then warns) or
cannot be loaded, :func:`native_available` is False, :func:`unavailable_reason` says why, and
constructing :class:`NativeSymplecticIntegrator` raises :class:`NativeUnavailableError`.
"""
from __future__ import annotations

import json
import os
import sys

import openmm as mm

_HERE = os.path.dirname(os.path.abspath(__file__))
KERNEL_NAME = "IntegrateSymPRKStep"


class NativeUnavailableError(RuntimeError):
    """The native plugin is not built or cannot be loaded here (the message says why)."""


class NativeMethodError(ValueError):
    """The method cannot run on the native backend (only kick/drift splittings and compositions can)."""


class _State:
    loaded = False
    swig = None
    reason = ""
    build_info: dict = {}
    build_dir = ""
    plugin_errors: dict = {}


def _build_dir() -> str:
    """The folder holding this package's native build.

    Normally this package's own folder.  When the package is imported from a source checkout that was
    installed non-editably (``pip install .`` then ``python -m pytest`` in the checkout, as CI does), the
    checkout shadows the installed copy and has no build outputs: the installed copy's folder is used then,
    and added to this package's ``__path__`` so that its extension module imports."""
    def built(d):
        return os.path.exists(os.path.join(d, "_build_info.json")) or os.path.exists(os.path.join(d, "_build_error.txt"))

    if built(_HERE):
        return _HERE
    candidates = []
    try:
        from importlib.metadata import distribution

        candidates.append(str(distribution("openmm_symprk").locate_file(os.path.join("openmm_symprk", "native"))))
    except Exception:
        pass
    candidates += [os.path.join(p or os.getcwd(), "openmm_symprk", "native") for p in sys.path]
    for d in candidates:
        if os.path.isdir(d) and os.path.realpath(d) != os.path.realpath(_HERE) and built(d):
            if d not in __path__:
                __path__.append(d)
            return d
    return _HERE


def _load() -> _State:
    st = _State
    if st.loaded:
        return st
    st.loaded = True
    where = _build_dir()
    st.build_dir = where
    info_path = os.path.join(where, "_build_info.json")
    error_path = os.path.join(where, "_build_error.txt")
    if not os.path.exists(info_path) and os.path.exists(error_path):
        with open(error_path) as fh:
            st.reason = "the native plugin failed to build at install time: " + fh.read().strip()
        return st
    if not os.path.exists(info_path):
        st.reason = ("the native plugin is not built (no openmm_symprk/native/_build_info.json): reinstall with "
                     "`pip install .` and read its warning, or run `python platforms/build_native.py` in a checkout")
        return st
    try:
        with open(info_path) as fh:
            st.build_info = json.load(fh)
    except Exception as exc:  # pragma: no cover - a damaged install
        st.reason = f"cannot read {info_path}: {exc}"
        return st
    running = mm.version.full_version
    built = st.build_info.get("openmm_version")
    if built != running:
        st.reason = (f"the native plugin was built against openmm {built} but openmm {running} is installed: "
                     f"reinstall openmm_symprk (`pip install .`) to rebuild it")
        return st
    try:
        from . import symprk_swig
    except Exception as exc:
        st.reason = f"the native plugin's Python module does not import: {exc}"
        return st
    libdir = os.path.join(where, "lib")
    present = set(_platform_names())
    for platform, name in st.build_info.get("libraries", {}).items():
        if platform == "api" or (platform != "Reference" and platform not in present):
            continue  # a kernel library is loaded only where OpenMM has its platform (CUDA needs libOpenMMCUDA)
        try:
            mm.Platform.loadPluginLibrary(os.path.join(libdir, name))
        except Exception as exc:
            st.plugin_errors[platform] = str(exc)
    if not any(_supports(p) for p in _platform_names()):
        errs = "; ".join(f"{k}: {v}" for k, v in st.plugin_errors.items()) or "no kernel library registered"
        st.reason = f"the native kernels did not load ({errs})"
        return st
    st.swig = symprk_swig
    return st


def _platform_names() -> list:
    return [mm.Platform.getPlatform(i).getName() for i in range(mm.Platform.getNumPlatforms())]


def _supports(name: str) -> bool:
    try:
        return bool(mm.Platform.getPlatformByName(name).supportsKernels([KERNEL_NAME]))
    except Exception:
        return False


def native_available() -> bool:
    """True if the plugin is built, matches the installed openmm, and its kernels are registered."""
    return _load().swig is not None


def unavailable_reason() -> str:
    """Why the native backend is unavailable ('' when it is available)."""
    return _load().reason


def native_platforms() -> list:
    """Names of the OpenMM platforms on which the native integrator runs in this process."""
    if not native_available():
        return []
    return [p for p in _platform_names() if _supports(p)]


def build_directory() -> str:
    """The folder holding the native build (``lib/``, the SWIG module, ``_build_info.json``)."""
    return _load().build_dir


def build_info() -> dict:
    """What the build made (libraries, skipped platforms with reasons, openmm version); {} if not built."""
    _load()
    return dict(_State.build_info)


def native_details() -> dict:
    """Per-platform backend notes for `symprk info`: {platform: 'native' or the reason it is not}."""
    st = _load()
    out = {}
    for p in _platform_names():
        if st.swig is not None and _supports(p):
            out[p] = "native"
        elif st.swig is None:
            out[p] = st.reason
        else:
            key = {"CPU": "Reference"}.get(p, p)
            out[p] = (st.plugin_errors.get(key) or st.build_info.get("skipped", {}).get(key)
                      or "no native kernel for this platform")
    return out


def _splitting_for(method, system):
    from ..systemcheck import has_constraints

    constraints = True if system is None else has_constraints(system)
    return method.constrained_splitting if constraints else method.splitting


def _make_class():
    from ..catalogue import get_method
    from ..integrators import SimulationBlowUpError, step_size_in_ps
    from ..systemcheck import validate_system

    base = _State.swig.SymPRKIntegrator

    class NativeSymplecticIntegrator(base):
        """A catalogue kick/drift method run by the native SymPRKIntegrator plugin.

        Parameters are those of :class:`openmm_symprk.SymplecticIntegrator` that apply to splittings:
        ``stepSize`` (time Quantity, or ps), ``method`` (catalogue name or alias), ``system`` (decides the
        RATTLE sequence -- compositions are taken over velocity Verlet under constraints -- and is checked
        for anything that breaks conservation), ``exact_momentum`` (project every kick's forces onto zero net
        force and torque; isolated systems only) and ``check_finite`` (``step`` raises SimulationBlowUpError
        when velocities stop being finite)."""

        def __init__(self, stepSize, method="verlet", system=None, exact_momentum=False, check_finite=True):
            dt = step_size_in_ps(stepSize)
            m = get_method(method)
            if not m.is_splitting:
                raise NativeMethodError(
                    f"method {m.name!r} is a general ({m.family}) PRK tableau; the native backend runs kick/drift "
                    f"splittings and compositions only. Use openmm_symprk.SymplecticIntegrator (CustomIntegrator "
                    f"backend) for it.")
            if system is not None:
                # the native kernels place virtual sites after every drift: no CustomIntegrator caveat
                validate_system(system, f"NativeSymplecticIntegrator({m.name})", exact_momentum,
                                skip=("virtualsites",))
            splitting = _splitting_for(m, system)
            coeffs = splitting.coefficients()
            kinds = [0 if label == "kick" else 1 for label, _ in coeffs]
            super().__init__(dt, kinds, [float(c) for _, c in coeffs])
            self.setMethodName(m.name)
            self.setExactMomentum(bool(exact_momentum))
            self.method = m
            self.method_name = m.name
            self.splitting = splitting
            self.check_finite = check_finite

        def setStepSize(self, size):
            return super().setStepSize(step_size_in_ps(size))

        def step(self, steps):
            """Advance ``steps`` steps; raise SimulationBlowUpError if the simulation blew up."""
            try:
                result = super().step(steps)
            except mm.OpenMMException as exc:
                if "NaN" not in str(exc):
                    raise
                raise self._blow_up(self.getStepsTaken(), "positions became NaN") from exc
            if self.check_finite:
                bad = self.getBlowUpStep()
                if bad:
                    raise self._blow_up(bad, "velocities became NaN, infinite or faster than 1e5 nm/ps")
            return result

        def _blow_up(self, step, what):
            import math

            st = self.method.stability
            stab = "unbounded" if st is None or math.isinf(st) else f"{st:.4f}"
            return SimulationBlowUpError(
                f"the simulation blew up at integrator step {step} with method {self.method_name!r} at step size "
                f"{self.getStepSize()} (native backend): {what}. Reduce the step size (largest stable h*omega for "
                f"this method: {stab}), or minimize the energy first. The Context still holds the non-finite "
                f"state; reload a checkpoint or positions saved before this call.")

        @property
        def steps_taken(self) -> int:
            return int(self.getStepsTaken())

        @property
        def force_evals(self) -> int:
            return int(self.getForceEvaluationsPerStep())

        def substeps(self) -> list:
            """[("kick"|"drift", coefficient)] as the plugin runs them."""
            return [("kick" if self.getSubstepKind(i) == 0 else "drift", self.getSubstepCoefficient(i))
                    for i in range(self.getNumSubsteps())]

        def describe(self) -> str:
            return (f"NativeSymplecticIntegrator: {self.method_name}, step {self.getStepSize()}, "
                    f"{self.getNumSubsteps()} sub-steps, force evaluations per step: {self.force_evals}, "
                    f"exact momentum: {self.getExactMomentum()}, platforms: {', '.join(native_platforms())}")

    return NativeSymplecticIntegrator




class _NativeMeta(type):
    """Calling the public name builds the real (SWIG-derived) class's instance; isinstance works on it."""

    def __call__(cls, stepSize, method="verlet", system=None, exact_momentum=False, check_finite=True):
        real = native_class()
        if real is None:
            raise NativeUnavailableError(f"the native backend is unavailable: {unavailable_reason()}")
        return real(stepSize, method, system=system, exact_momentum=exact_momentum, check_finite=check_finite)

    def __instancecheck__(cls, obj):
        real = native_class()
        return real is not None and isinstance(obj, real)


class NativeSymplecticIntegrator(metaclass=_NativeMeta):
    """NativeSymplecticIntegrator(stepSize, method="verlet", system=None, exact_momentum=False, check_finite=True)

    A catalogue kick/drift method on the native plugin (an ``openmm.Integrator``); see
    ``native_class().__doc__``.  Raises NativeUnavailableError when the plugin is not available, and the
    same errors as SymplecticIntegrator for bad step sizes and unknown methods."""


_CLASS = None


def native_class():
    """The NativeSymplecticIntegrator class itself (for isinstance checks); None when unavailable."""
    global _CLASS
    if not native_available():
        return None
    if _CLASS is None:
        _CLASS = _make_class()
    return _CLASS


def as_native(integrator):
    """An ``openmm.Integrator`` that is a SymPRKIntegrator (e.g. from XmlSerializer.deserialize), seen as one.

    The returned object takes over ownership of the C++ integrator."""
    if not native_available():
        raise NativeUnavailableError(f"the native backend is unavailable: {unavailable_reason()}")
    S = _State.swig.SymPRKIntegrator
    if isinstance(integrator, S):
        return integrator
    if not S.isinstance(integrator):
        raise TypeError(f"{type(integrator).__name__} is not a SymPRKIntegrator")
    own = bool(getattr(integrator, "thisown", False))
    result = S.cast(integrator)
    if own:
        integrator.thisown = False
        result.thisown = True
    return result


def deserialize_integrator(xml: str):
    """XmlSerializer.deserialize for a serialized SymPRKIntegrator (returns the SWIG class)."""
    return as_native(mm.XmlSerializer.deserialize(xml))


__all__ = ["native_available", "native_platforms", "unavailable_reason", "build_info", "native_details",
           "NativeSymplecticIntegrator", "native_class", "as_native", "deserialize_integrator",
           "NativeUnavailableError", "NativeMethodError"]
