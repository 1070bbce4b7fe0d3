"""The compiled OpenMM plugin (``platforms/``, built by ``pip install .`` into this folder) and its loader.

This module knows where the build is, loads the kernel libraries for the platforms OpenMM has in this
process, and says why the native backend is unavailable when it is, with the one command that fixes it.
It imports nothing else of the package; :mod:`openmm_symprk.integrators.native_backend` builds the integrator
class on the SWIG class it exposes.

``SYMPRK_NATIVE_PLATFORMS`` (comma-separated platform names, e.g. ``Reference,CPU``) limits the platforms
whose kernels are loaded; the others then report why, and the native integrator refuses them with a clear
error (``backend="auto"`` then picks the CustomIntegrator program, which runs everywhere).

Build outputs here: ``lib/libOpenMMSymPRK*.so``, ``symprk_swig.py`` + ``symprk_swig_ext*.so``,
``_build_info.json`` (what was built, against which openmm, and why a platform kernel was skipped), or
``_build_error.txt`` when the build failed.
"""
from __future__ import annotations

import json
import os

import openmm as mm

from ..support.errors import SymprkError

HERE = os.path.dirname(os.path.abspath(__file__))
KERNEL_NAME = "IntegrateSymPRKStep"
#: Kernel library per platform name ("Reference" also serves CPU, which derives from it).
SERVES = {"Reference": ("Reference", "CPU"), "OpenCL": ("OpenCL",), "CUDA": ("CUDA",)}
#: The command that rebuilds the plugin of an installation from its source checkout.
REBUILD = "pip install --force-reinstall --no-deps <path of your openmm_symprk checkout>"

__all__ = ["available", "unavailable_reason", "fix_hint", "platforms", "thermostat_platforms", "details", "build_info", "build_directory",
           "swig_module", "NativeUnavailableError", "KERNEL_NAME"]


class NativeUnavailableError(SymprkError, RuntimeError):
    """The native plugin is not built or cannot be loaded here (the message says why and how to fix it)."""


class _State:
    loaded = False
    swig = None
    reason = ""
    build_info: dict = {}
    plugin_errors: dict = {}


def _platform_names() -> list:
    return [mm.Platform.getPlatform(i).getName() for i in range(mm.Platform.getNumPlatforms())]


def _supports(name: str) -> bool:
    try:
        return bool(mm.Platform.getPlatformByName(name).supportsKernels([KERNEL_NAME]))
    except Exception:
        return False


def _major_minor(version: str) -> tuple:
    parts = version.split(".")
    return tuple(parts[:2])


def _load() -> type:
    st = _State
    if st.loaded:
        return st
    st.loaded = True
    info_path = os.path.join(HERE, "_build_info.json")
    error_path = os.path.join(HERE, "_build_error.txt")
    if not os.path.exists(info_path):
        if os.path.exists(error_path):
            with open(error_path) as fh:
                st.reason = "the native plugin failed to build at install time: " + fh.read().strip()
        else:
            st.reason = (f"the native plugin is not built in {HERE} (a source checkout imported without an "
                         f"editable install, or an install made with SYMPRK_NATIVE=0)")
        return st
    try:
        with open(info_path) as fh:
            st.build_info = json.load(fh)
    except Exception as exc:  # pragma: no cover - a damaged install
        st.reason = f"cannot read {info_path}: {exc}"
        return st
    running, built = mm.version.full_version, st.build_info.get("openmm_version", "?")
    if _major_minor(built) != _major_minor(running):
        st.reason = (f"the native plugin was built against openmm {built} but openmm {running} is installed "
                     f"(plugins are tied to an openmm minor series)")
        return st
    try:
        from . import symprk_swig
    except Exception as exc:
        st.reason = f"the native plugin's Python module does not import: {exc}"
        return st
    present = set(_platform_names())
    wanted = os.environ.get("SYMPRK_NATIVE_PLATFORMS", "").strip()
    wanted = {p.strip() for p in wanted.split(",") if p.strip()} if wanted else None
    for platform, name in st.build_info.get("libraries", {}).items():
        if platform == "api" or not (set(SERVES.get(platform, (platform,))) & present):
            continue  # a kernel library is loaded only where OpenMM has its platform (CUDA needs libOpenMMCUDA)
        if wanted is not None and not (set(SERVES.get(platform, (platform,))) & wanted):
            st.plugin_errors[platform] = (f"not loaded: SYMPRK_NATIVE_PLATFORMS={os.environ['SYMPRK_NATIVE_PLATFORMS']} "
                                          f"leaves it out")
            continue
        try:
            mm.Platform.loadPluginLibrary(os.path.join(HERE, "lib", name))
        except Exception as exc:
            st.plugin_errors[platform] = str(exc)
    if not any(_supports(p) for p in present):
        errs = "; ".join(f"{k}: {v}" for k, v in st.plugin_errors.items()) or "no kernel library registered"
        st.reason = f"the native kernels did not load ({errs})"
        return st
    st.swig = symprk_swig
    symprk_swig.SymPRKIntegrator.registerMissingKernelFactories()
    return st


def available() -> bool:
    """True if the plugin is built, matches the installed openmm, and has a kernel for some platform."""
    return _load().swig is not None


def unavailable_reason() -> str:
    """Why the native backend is unavailable ('' when it is available)."""
    return _load().reason


def fix_hint(reason: str | None = None) -> str:
    """The one command (and what it needs) that makes the native backend available."""
    reason = unavailable_reason() if reason is None else reason
    if "no C++ compiler" in reason:
        return f"install a C++17 compiler (e.g. `apt-get install g++`), then run `{REBUILD}`"
    if "SYMPRK_NATIVE=0: native build disabled" in reason:
        return f"unset SYMPRK_NATIVE and run `{REBUILD}`"
    return f"run `{REBUILD}` and read the warning it prints (add -v to see the build log)"


def swig_module():
    """The SWIG module of the plugin (``symprk_swig``), or None when the plugin is unavailable."""
    return _load().swig


def platforms() -> list:
    """Names of the OpenMM platforms on which the native integrator has a real kernel in this process."""
    st = _load()
    if st.swig is None:
        return []
    return [p for p in _platform_names() if _has_kernel(p)]


def thermostat_platforms() -> list:
    """Names of the platforms on which the native integrator runs the velocity-rescaling thermostat
    (``temperature=``): every platform with a kernel, when the build has the thermostat (SymPRKIntegrator.setThermostat)."""
    st = _load()
    if st.swig is None or not hasattr(st.swig.SymPRKIntegrator, "setThermostat"):
        return []
    return platforms()


def _library_of(platform: str) -> str:
    return next((lib for lib, served in SERVES.items() if platform in served), platform)


def _has_kernel(platform: str) -> bool:
    """A real kernel (not the stand-in that only raises a clear error) serves ``platform``."""
    lib = _library_of(platform)
    return (lib in _State.build_info.get("libraries", {}) and lib not in _State.plugin_errors
            and _supports(platform))


def details() -> dict:
    """Per platform of this process: "native", or why the native integrator has no kernel there."""
    st = _load()
    out = {}
    for p in _platform_names():
        if st.swig is None:
            out[p] = st.reason
        elif _has_kernel(p):
            out[p] = "native"
        else:
            lib = _library_of(p)
            out[p] = (st.plugin_errors.get(lib) or st.build_info.get("skipped", {}).get(lib)
                      or f"openmm_symprk has no kernel for the {p} platform")
    return out


def build_info() -> dict:
    """What the build made (libraries, skipped platforms with reasons, openmm version); {} if not built."""
    _load()
    return dict(_State.build_info)


def build_directory() -> str:
    """The folder holding the native build (``lib/``, the SWIG module, ``_build_info.json``)."""
    return HERE
