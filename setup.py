"""Packaging for openmm_symprk: `pip install .` (extras: see EXTRAS below; `[test]` for the test-suite).

The build also compiles the native OpenMM plugin with CMake (platforms/CMakeLists.txt) against the openmm of
the build environment (pyproject.toml pins it to the runtime's minor series).  The CMake build folder,
build/native-<python>-<platform>/, persists between installs, so that an editable reinstall recompiles only
what changed; its tests/ folder holds the C++ tests (tests/plugin/test_cpp.py runs them).  If the native
build fails for any reason the package still installs and works through the CustomIntegrator backend: the
build prints a warning and writes the reason to openmm_symprk/plugin/_build_error.txt, which
openmm_symprk.plugin.unavailable_reason() reports.  SYMPRK_NATIVE=0 skips the native build.
"""
import filecmp
import json
import os
import re
import shutil
import subprocess
import sys
import sysconfig
import time
import traceback

from setuptools import Distribution, find_packages, setup
from setuptools.command.build_ext import build_ext

HERE = os.path.dirname(os.path.abspath(__file__))
PLATFORMS = os.path.join(HERE, "platforms")
#: Kernel libraries whose failure to build leaves the rest of the plugin working (CMake target per platform).
OPTIONAL_TARGETS = {"OpenCL": "OpenMMSymPRKOpenCL", "CUDA": "OpenMMSymPRKCUDA"}
CORE_TARGETS = ["OpenMMSymPRK", "OpenMMSymPRKReference", "symprk_swig_ext"]
TEST_TARGETS = ["TestSerializeSymPRKIntegrator", "TestReferenceSymPRKStep", "TestReferenceSymPRKThermostat",
                "TestReferenceSymPRKStepPlan"]
OUTPUTS = ["_build_info.json", "_build_error.txt", "symprk_swig.py"]


class NativeBuildError(RuntimeError):
    """The native plugin cannot be built here (the message says why)."""


def version() -> str:
    """The package's version, from openmm_symprk/__init__.py (its only definition)."""
    with open(os.path.join(HERE, "openmm_symprk", "__init__.py"), encoding="utf-8") as fh:
        match = re.search(r'^__version__\s*=\s*["\']([^"\']+)["\']', fh.read(), re.M)
    if match is None:
        raise RuntimeError("openmm_symprk/__init__.py defines no __version__")
    return match.group(1)


def build_directory() -> str:
    """The persistent CMake build folder of this interpreter and platform."""
    return os.path.join(HERE, "build", f"native-{sys.implementation.cache_tag}-{sysconfig.get_platform()}")


# -- the native build ---------------------------------------------------------------------------------------
def _disabled() -> bool:
    return os.environ.get("SYMPRK_NATIVE", "1").strip().lower() in ("0", "no", "off", "false")


def _run(cmd, what):
    res = subprocess.run(cmd, stdout=subprocess.PIPE, stderr=subprocess.STDOUT, text=True)
    if res.returncode != 0:
        out = res.stdout[-6000:]
        if "No CMAKE_CXX_COMPILER could be found" in out or "is not a full path to an existing compiler" in out:
            raise NativeBuildError("no C++ compiler: CMake found none (install g++ or clang++, or set CXX)\n" + out)
        raise NativeBuildError(f"{what} failed:\n{' '.join(cmd)}\n{out}")
    return res.stdout


def _tool(name: str, module: str, attribute: str) -> str | None:
    """A build tool: the one on PATH (pip puts the build environment's first), else the PyPI package's binary."""
    found = shutil.which(name)
    if found:
        return found
    try:
        exe = os.path.join(getattr(__import__(module), attribute), name)
    except Exception:
        return None
    return next((p for p in (exe, exe + ".exe") if os.path.exists(p)), None)


def _package_include(module: str) -> str | None:
    """The ``include`` folder of an installed NVIDIA header package (e.g. nvidia.cuda_opencl), or None."""
    try:
        import importlib

        mod = importlib.import_module(module)
    except Exception:
        return None
    for base in list(getattr(mod, "__path__", [])):
        if os.path.isdir(os.path.join(base, "include")):
            return os.path.join(base, "include")
    return None


def _mirror(src: str, dst: str, keep=lambda rel: True) -> str:
    """Copy the files of ``src`` into ``dst`` where they differ, leaving identical files untouched.

    pip builds every install in a new temporary environment, so OpenMM's headers and the NVIDIA headers move
    each time; compiling against a stable copy in the build folder keeps the compile commands (and the object
    files) the same from one install to the next."""
    for root, _, files in os.walk(src):
        for name in files:
            rel = os.path.relpath(os.path.join(root, name), src)
            if not keep(rel):
                continue
            source, target = os.path.join(src, rel), os.path.join(dst, rel)
            if os.path.exists(target) and filecmp.cmp(source, target, shallow=False):
                continue
            os.makedirs(os.path.dirname(target), exist_ok=True)
            shutil.copyfile(source, target)  # a new modification time: what depends on it is rebuilt
            shutil.copymode(source, target)
    return dst


def _openmm_sdk(build_dir: str) -> tuple:
    """(folder with include/ and lib/ mirrored from the build environment's openmm, openmm's version)."""
    try:
        import openmm.version as v
    except Exception as exc:
        raise NativeBuildError(f"openmm is not installed in the build environment ({exc}); it is a build "
                               "requirement (pyproject.toml)") from exc
    lib = v.openmm_library_path
    include = os.path.join(os.path.dirname(lib), "include")
    if not os.path.exists(os.path.join(include, "openmm", "Integrator.h")):
        raise NativeBuildError(f"the openmm at {lib} ships no C++ headers (expected {include}/openmm)")
    sdk = os.path.join(build_dir, "openmm-sdk")
    _mirror(include, os.path.join(sdk, "include"))
    wanted = re.compile(r"^(lib)?OpenMM\.|^plugins[/\\](lib)?OpenMM(OpenCL|CUDA)\.")
    _mirror(lib, os.path.join(sdk, "lib"), lambda rel: bool(wanted.match(rel)))
    return sdk, v.full_version


def _header_dirs(build_dir: str) -> list:
    """CMake definitions for the OpenCL and CUDA headers of PyPI's NVIDIA packages (build requirements on Linux
    x86_64), mirrored into the build folder; none where the packages are absent (CMake then searches the system)."""
    defs = []
    opencl = _package_include("nvidia.cuda_opencl")
    if opencl and os.path.exists(os.path.join(opencl, "CL", "opencl.h")):
        defs.append(f"-DSYMPRK_OPENCL_INCLUDE={_mirror(opencl, os.path.join(build_dir, 'headers', 'opencl'))}")
    runtime, nvcc = _package_include("nvidia.cuda_runtime"), _package_include("nvidia.cuda_nvcc")
    if runtime and nvcc and os.path.exists(os.path.join(runtime, "cuda.h")):
        dirs = [_mirror(runtime, os.path.join(build_dir, "headers", "cuda-runtime")),
                _mirror(nvcc, os.path.join(build_dir, "headers", "cuda-nvcc"))]
        defs.append("-DSYMPRK_CUDA_INCLUDE=" + ";".join(dirs))
    return defs


def _configure(cmake: str, build_dir: str, sdk: str, omm_version: str) -> None:
    ninja = _tool("ninja", "ninja", "BIN_DIR")
    generator = "Ninja" if ninja else None
    cache = os.path.join(build_dir, "CMakeCache.txt")
    if os.path.exists(cache):  # a folder configured by another generator or for another source cannot be reused
        with open(cache, encoding="utf-8", errors="replace") as fh:
            text = fh.read()
        home = re.search(r"^CMAKE_HOME_DIRECTORY:INTERNAL=(.*)$", text, re.M)
        gen = re.search(r"^CMAKE_GENERATOR:INTERNAL=(.*)$", text, re.M)
        if (home and os.path.normcase(os.path.realpath(home.group(1))) != os.path.normcase(os.path.realpath(PLATFORMS))) \
                or (generator and gen and gen.group(1) != generator):
            for sub in ("CMakeCache.txt", "CMakeFiles"):
                path = os.path.join(build_dir, sub)
                shutil.rmtree(path) if os.path.isdir(path) else os.remove(path)
    cmd = [cmake, "-S", PLATFORMS, "-B", build_dir, f"-DPython_EXECUTABLE={sys.executable}",
           f"-DOPENMM_DIR={sdk}", f"-DOPENMM_VERSION={omm_version}", "-USWIG_*", "-UOPENMM_OPENCL_LIBRARY",
           "-UOPENMM_LIBRARY"]
    if generator:
        cmd += ["-G", generator, f"-DCMAKE_MAKE_PROGRAM={ninja}"]
    swig = shutil.which("swig")  # PyPI's swig (a build requirement) puts it on the build environment's PATH
    if swig:
        cmd.append(f"-DSWIG_EXECUTABLE={swig}")
    _run(cmd + _header_dirs(build_dir), "configuring the native plugin (CMake)")


def build_native(target: str, build_dir: str, log=print) -> dict:
    """Configure and build the plugin in ``build_dir`` and install it into ``target`` (openmm_symprk/plugin).

    The API, Reference and SWIG parts must build; a platform kernel (OpenCL, CUDA) that does not is left out,
    with the reason in _build_info.json.  Raises NativeBuildError with the reason when nothing usable was built."""
    if _disabled():
        raise NativeBuildError("SYMPRK_NATIVE=0: native build disabled by the environment")
    cxx = os.environ.get("CXX")
    if cxx and shutil.which(cxx.split()[0]) is None:
        raise NativeBuildError(f"no C++ compiler: CXX={cxx!r} not found (install g++ or clang++)")
    cmake = _tool("cmake", "cmake", "CMAKE_BIN_DIR")
    if cmake is None:
        raise NativeBuildError("CMake is not installed (it is a build requirement: pip install cmake)")
    t0 = time.time()
    os.makedirs(build_dir, exist_ok=True)
    sdk, omm_version = _openmm_sdk(build_dir)
    _configure(cmake, build_dir, sdk, omm_version)
    with open(os.path.join(build_dir, "_build_info.json")) as fh:
        info = json.load(fh)
    jobs = ["--parallel", str(os.cpu_count() or 1)]
    _run([cmake, "--build", build_dir, "--target", *CORE_TARGETS, *jobs], "building the native plugin")
    for platform in list(info["libraries"]):
        if platform in OPTIONAL_TARGETS:
            try:
                _run([cmake, "--build", build_dir, "--target", OPTIONAL_TARGETS[platform], *jobs],
                     f"building the {platform} kernel")
            except NativeBuildError as exc:
                info["libraries"].pop(platform)
                info["skipped"][platform] = str(exc).splitlines()[0] + " (see the build log: pip install -v)"
                log(f"openmm_symprk native: {platform} kernel left out: {exc}")
    try:  # the C++ tests stay in the build folder (tests/plugin/test_cpp.py runs them)
        _run([cmake, "--build", build_dir, "--target", *TEST_TARGETS, *jobs], "building the C++ tests")
    except NativeBuildError as exc:
        log(f"openmm_symprk native: the C++ tests did not build: {exc}")
    clean(target)
    for component in ["core"] + [p for p in OPTIONAL_TARGETS if p in info["libraries"]]:
        _run([cmake, "--install", build_dir, "--prefix", target, "--component", component],
             f"installing the native plugin ({component})")
    info["seconds"] = round(time.time() - t0, 1)
    with open(os.path.join(target, "_build_info.json"), "w") as fh:
        fh.write(json.dumps(info, indent=2) + "\n")
    skipped = "".join(f"; {k} left out: {v}" for k, v in info["skipped"].items())
    log(f"openmm_symprk native: built in {info['seconds']} s against openmm {omm_version} (platform kernels: "
        f"{', '.join(k for k in info['libraries'] if k != 'api')}{skipped})")
    return info


def clean(target: str) -> None:
    """Remove a previous build's outputs from ``target`` (the openmm_symprk/plugin folder)."""
    if not os.path.isdir(target):
        return
    for name in OUTPUTS + [f for f in os.listdir(target) if f.startswith("symprk_swig_ext")]:
        path = os.path.join(target, name)
        if os.path.exists(path):
            os.remove(path)
    if os.path.isdir(os.path.join(target, "lib")):
        shutil.rmtree(os.path.join(target, "lib"))


def build_or_warn(target: str, build_dir: str, log=print) -> bool:
    """build_native, turning any failure into a warning and openmm_symprk/plugin/_build_error.txt."""
    os.makedirs(target, exist_ok=True)
    try:
        build_native(target, build_dir, log)
        return True
    except Exception as exc:  # noqa: BLE001 - any failure must leave the pure-Python install working
        reason = str(exc) if isinstance(exc, NativeBuildError) else traceback.format_exc()
        clean(target)
        with open(os.path.join(target, "_build_error.txt"), "w") as fh:
            fh.write(reason)
        bar = "=" * 78
        sys.stderr.write(f"\n{bar}\nWARNING: openmm_symprk's native plugin was not built; the package installs "
                         f"and works\nthrough the CustomIntegrator backend only.\nReason: {reason.strip()}\n{bar}\n\n")
        return False


class BuildNative(build_ext):
    """Build the native plugin into the package (in place for editable installs); never fail the install."""

    def run(self):
        inplace = bool(self.inplace or getattr(self, "editable_mode", False))
        target = os.path.join(HERE if inplace else self.build_lib, "openmm_symprk", "plugin")
        build_or_warn(target, build_directory(), log=lambda msg: sys.stderr.write(msg + "\n"))

    def get_outputs(self):
        return []


class BinaryDistribution(Distribution):
    """The wheel carries compiled libraries: platform-specific, and build_ext always runs."""

    def has_ext_modules(self):
        return True


#: Optional dependencies by use; the core (integrators, methods, rigid bodies, diagnostics, `symprk demo`) needs
#: only openmm, numpy and scipy.  The package names the extra in its error when a missing one is used.
EXTRAS = {
    "analysis": ["MDAnalysis>=2.7", "scipy>=1.10", "tqdm>=4.60"],
    "studies": ["matplotlib>=3.7", "tqdm>=4.60", "pymbar>=4", "scipy>=1.10", "MDAnalysis>=2.7"],
    "cluster": ["dask[distributed]>=2023.1"],
    "cuda12": ["openmm-cuda-12>=8.6,<8.7"],
}
EXTRAS["all"] = sorted(set(EXTRAS["analysis"] + EXTRAS["studies"]))
# the documentation site: Sphinx, MyST and a theme (docs/conf.py subclasses Sphinx's Python domain, so Sphinx's major
# version is pinned), and everything `all` installs, since the API reference imports every module
EXTRAS["docs"] = sorted(set(["sphinx>=8,<10", "myst-parser>=4", "furo>=2024.1"] + EXTRAS["all"]))
#: The test-suite cross-checks the analyses against MDAnalysis' test files and the MDAKits that compute the same.
CROSS_CHECKS = ["MDAnalysisTests>=2.7", "waterdynamics>=1.2", "transport-analysis>=0.1.2", "tidynamics>=1.1"]
# PyYAML reads mdakit/metadata.yaml, the MDAKits registry's entry, in its test
EXTRAS["test"] = sorted(set(["pytest>=7", "pyelftools>=0.29", "pyyaml>=6"] + EXTRAS["all"] + EXTRAS["cluster"]
                            + CROSS_CHECKS))

if __name__ == "__main__":
    setup(
        name="openmm_symprk",
        version=version(),
        description="Symplectic partitioned Runge-Kutta and RATTLE integrators for OpenMM, "
                    "with exact momentum conservation and conservation diagnostics",
        long_description=open(os.path.join(HERE, "README.md"), encoding="utf-8").read()
        if os.path.exists(os.path.join(HERE, "README.md")) else "",
        long_description_content_type="text/markdown",
        python_requires=">=3.11",
        packages=find_packages(include=["openmm_symprk", "openmm_symprk.*"]),
        package_data={"openmm_symprk.methods": ["data/*.toml"]},
        install_requires=["openmm>=8.6,<8.7", "numpy>=1.24"],
        extras_require=EXTRAS,
        entry_points={"console_scripts": ["symprk=openmm_symprk.cli:main"]},
        cmdclass={"build_ext": BuildNative},
        distclass=BinaryDistribution,
        classifiers=[
            "Programming Language :: Python :: 3",
            "Topic :: Scientific/Engineering :: Chemistry",
            "Topic :: Scientific/Engineering :: Physics",
        ],
    )
