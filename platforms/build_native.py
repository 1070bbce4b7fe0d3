"""Build the openmm_symprk native plugin against the installed openmm wheel.

Used by setup.py (``pip install .``) and runnable by hand for development::

    python platforms/build_native.py            # builds into openmm_symprk/plugin/ (in place)

What it builds (g++ directly, C++17, the wheel's headers under OpenMM.libs/include, new C++11 ABI):

* ``lib/libOpenMMSymPRK.so``          the API library: SymPRKIntegrator, the abstract kernel, the XML proxy
* ``lib/libOpenMMSymPRKReference.so`` Reference kernel + factory (serves the CPU platform too)
* ``lib/libOpenMMSymPRKOpenCL.so``    Common kernel + OpenCL factory (the OpenCL C headers come from PyPI's
  nvidia-cuda-opencl-cu12, a build requirement on Linux x86_64, or from the system)
* ``lib/libOpenMMSymPRKCUDA.so``      Common kernel + CUDA factory (cuda.h from PyPI's nvidia-cuda-runtime-cu12 and
  nvidia-cuda-nvcc-cu12, build requirements on Linux x86_64, or CUDA_HOME); it links against OpenMM
  only, so it builds and loads without a GPU and serves OpenMM's CUDA platform wherever that is
  installed (``pip install "openmm_symprk[cuda12]"``)
* ``symprk_swig.py`` + ``symprk_swig_ext<ext>`` the SWIG wrapper (SWIG >= 4.4, PyPI ``swig``)
* ``_build_info.json``                what was built, against which openmm, and why anything was skipped

Every failure raises NativeBuildError with the reason; setup.py turns it into a warning and installs the
pure-Python package (a platform kernel that cannot be built is skipped with its reason in
``_build_info.json``).  Environment: CXX (compiler, default g++), SYMPRK_NATIVE=0 (skip the build),
SYMPRK_OPENCL_INCLUDE (a folder holding CL/opencl.h), CUDA_HOME (a CUDA toolkit).
"""
from __future__ import annotations

import json
import os
import re
import shutil
import subprocess
import sys
import sysconfig
import tempfile
import time
from concurrent.futures import ThreadPoolExecutor
from pathlib import Path

HERE = Path(__file__).resolve().parent
SWIG_MIN = (4, 4)


class NativeBuildError(RuntimeError):
    """The native plugin cannot be built here (the message says why)."""


# -- locating the tools -------------------------------------------------------------------------------------
_PROBE = ("import json, os, openmm, openmm.version as v; lib = v.openmm_library_path; "
          "print(json.dumps({'lib': lib, 'version': v.full_version, 'short': v.short_version, "
          "'package': os.path.dirname(openmm.__file__)}))")


def locate_openmm() -> dict:
    """The openmm wheel to build against: library folder, include folder, plugin folder, version.

    The openmm installed for the interpreter the package will run with comes first (under pip's build
    isolation this process sees only the build environment, so that interpreter is asked in a subprocess
    without the isolation's path settings); when it has none yet (a fresh install: pip installs the
    package's dependencies after building it), the openmm of the build environment is used, which
    pyproject.toml pins to the same minor series as the runtime requirement."""
    info = None
    env = {k: val for k, val in os.environ.items() if k not in ("PYTHONPATH", "PYTHONNOUSERSITE", "PYTHONHOME")}
    for exe in dict.fromkeys([sys.executable, getattr(sys, "_base_executable", sys.executable)]):
        try:
            out = subprocess.run([exe, "-c", _PROBE], capture_output=True, text=True, env=env, timeout=120)
        except Exception:
            continue
        if out.returncode == 0 and out.stdout.strip():
            info = json.loads(out.stdout.strip().splitlines()[-1])
            info["origin"] = "target environment"
            break
    if info is None:
        try:
            import openmm.version as v  # noqa: F401
            import openmm

            info = {"lib": v.openmm_library_path, "version": v.full_version, "short": v.short_version,
                    "package": os.path.dirname(openmm.__file__), "origin": "build environment"}
        except Exception:
            pass
    if info is None:
        raise NativeBuildError("openmm is not installed for this Python (pip installs it with the package; "
                               "rebuild with `pip install .` once it is there)")
    lib = Path(info["lib"])
    inc = lib.parent / "include"
    if not (inc / "openmm" / "Integrator.h").exists():
        raise NativeBuildError(f"the openmm wheel at {lib} ships no C++ headers (expected {inc}/openmm)")
    if not (lib / "libOpenMM.so").exists():
        raise NativeBuildError(f"libOpenMM.so not found in {lib}")
    info.update(lib=str(lib), include=str(inc), plugins=str(lib / "plugins"))
    return info


def find_swig() -> str:
    candidates = [shutil.which("swig"), shutil.which("swig4.0")]
    try:  # the PyPI package puts its binary next to the interpreter's scripts
        import swig  # type: ignore

        candidates.insert(0, os.path.join(getattr(swig, "BIN_DIR", ""), "swig"))
    except Exception:
        pass
    found = []
    for exe in candidates:
        if not exe or not os.path.exists(exe):
            continue
        try:
            out = subprocess.run([exe, "-version"], capture_output=True, text=True, timeout=60).stdout
        except Exception:
            continue
        m = re.search(r"SWIG Version (\d+)\.(\d+)", out)
        if m:
            ver = (int(m.group(1)), int(m.group(2)))
            if ver >= SWIG_MIN:
                return exe
            found.append(f"{exe} ({ver[0]}.{ver[1]})")
    raise NativeBuildError(
        "SWIG >= 4.4 is needed to wrap the plugin for Python (the openmm wheel's wrappers use SWIG's runtime "
        f"version 5): `pip install 'swig>=4.4'`; found {', '.join(found) or 'none'}")


def _cxx() -> list:
    cxx = os.environ.get("CXX", "g++")
    exe = shutil.which(cxx.split()[0])
    if exe is None:
        raise NativeBuildError(f"no C++ compiler: {cxx!r} not found (install g++)")
    return cxx.split()


def _package_include(module: str) -> str | None:
    """The ``include`` folder of an installed NVIDIA header package (e.g. nvidia.cuda_opencl), or None."""
    try:
        import importlib

        mod = importlib.import_module(module)
    except Exception:
        return None
    for base in list(getattr(mod, "__path__", [])) + [os.path.dirname(getattr(mod, "__file__", "") or "")]:
        if base and os.path.isdir(os.path.join(base, "include")):
            return os.path.join(base, "include")
    return None


def _opencl_include() -> str | None:
    """A folder holding CL/opencl.h: SYMPRK_OPENCL_INCLUDE, the headers of PyPI's nvidia-cuda-opencl-cu12
    (a build requirement on Linux x86_64), or the system's (Debian: opencl-c-headers)."""
    for d in filter(None, [os.environ.get("SYMPRK_OPENCL_INCLUDE"), _package_include("nvidia.cuda_opencl"),
                           "/usr/include", "/usr/local/include",
                           os.path.join(os.environ.get("CUDA_HOME", "/usr/local/cuda"), "include")]):
        if os.path.exists(os.path.join(d, "CL", "opencl.h")):
            return d
    return None


def _cuda_includes() -> list | None:
    """Folders holding cuda.h and crt/host_defines.h: CUDA_HOME, a toolkit in /usr/local/cuda, or the headers
    of PyPI's nvidia-cuda-runtime-cu12 and nvidia-cuda-nvcc-cu12 (build requirements on Linux x86_64)."""
    for home in filter(None, [os.environ.get("CUDA_HOME"), "/usr/local/cuda"]):
        inc = os.path.join(home, "include")
        if os.path.exists(os.path.join(inc, "cuda.h")) and os.path.exists(os.path.join(inc, "crt", "host_defines.h")):
            return [inc]
    runtime, nvcc = _package_include("nvidia.cuda_runtime"), _package_include("nvidia.cuda_nvcc")
    if runtime and nvcc and os.path.exists(os.path.join(runtime, "cuda.h")) and \
            os.path.exists(os.path.join(nvcc, "crt", "host_defines.h")):
        return [runtime, nvcc]
    return None


# -- the build ----------------------------------------------------------------------------------------------
class _Builder:
    def __init__(self, omm: dict, out: Path, tmp: Path, log):
        self.omm, self.out, self.tmp, self.log = omm, out, tmp, log
        self.cxx = _cxx()
        inc = Path(omm["include"])
        self.includes = [inc, inc / "openmm", inc / "openmm" / "reference", inc / "openmm" / "common",
                         HERE / "openmmapi" / "include", HERE / "serialization" / "include",
                         HERE / "reference" / "src", HERE / "common" / "src"]
        self.cflags = ["-std=c++17", "-O2", "-fPIC", "-ffp-contract=off", "-DNDEBUG", "-Wno-deprecated-declarations",
                       "-Wno-ignored-attributes"]
        self.lib_dir = out / "lib"
        self.lib_dir.mkdir(parents=True, exist_ok=True)
        self.tmp.mkdir(parents=True, exist_ok=True)
        # Run paths: our own folder, the wheel's folders relative to site-packages, and the absolute paths
        # this was built against (editable installs and unusual layouts).
        self.rpath_lib = ["$ORIGIN", "$ORIGIN/../../../OpenMM.libs/lib", "$ORIGIN/../../../OpenMM.libs/lib/plugins",
                          omm["lib"], omm["plugins"]]

    def compile(self, sources: list, extra_includes=(), extra_flags=()) -> list:
        objs = []
        jobs = []
        for src in sources:
            src = Path(src)
            obj = self.tmp / (re.sub(r"[^A-Za-z0-9]+", "_", str(src.relative_to(HERE) if HERE in src.parents else src.name)) + ".o")
            objs.append(obj)
            cmd = self.cxx + self.cflags + list(extra_flags) + [f"-I{d}" for d in list(extra_includes) + self.includes] + [
                "-c", str(src), "-o", str(obj)]
            jobs.append((cmd, src))
        with ThreadPoolExecutor(max_workers=max(1, os.cpu_count() or 1)) as pool:
            for cmd, src, res in pool.map(lambda j: (j[0], j[1], subprocess.run(j[0], capture_output=True, text=True)), jobs):
                if res.returncode != 0:
                    raise NativeBuildError(f"compiling {src.name} failed:\n{' '.join(cmd)}\n{res.stderr[-4000:]}")
        return objs

    def link(self, objs: list, target: Path, libs: list, libdirs: list, rpath: list, extra=()):
        cmd = self.cxx + ["-shared", "-o", str(target)] + [str(o) for o in objs] + [f"-L{d}" for d in libdirs] + \
            [f"-l{lib}" for lib in libs] + [f"-Wl,-rpath,{r}" for r in rpath] + ["-Wl,--enable-new-dtags"] + list(extra)
        res = subprocess.run(cmd, capture_output=True, text=True)
        if res.returncode != 0:
            raise NativeBuildError(f"linking {target.name} failed:\n{' '.join(cmd)}\n{res.stderr[-4000:]}")
        self.log(f"  built {target.relative_to(self.out.parent.parent) if self.out.parent.parent in target.parents else target}")


def _embed_kernel_sources(tmp: Path) -> Path:
    """CommonSymPRKKernelSources.cpp: the device source as a C++ string (raw literals split under 16 kB)."""
    text = (HERE / "common" / "src" / "kernels" / "symprk.cc").read_text()
    chunks = [text[i:i + 12000] for i in range(0, len(text), 12000)]
    body = "\n".join(f'    R"SYMPRKSRC({c})SYMPRKSRC"' for c in chunks)
    path = tmp / "CommonSymPRKKernelSources.cpp"
    path.write_text('#include "CommonSymPRKKernels.h"\n'
                    f"const std::string OpenMM::CommonSymPRKKernelSources::symprk = std::string(\n{body}\n);\n")
    return path


def build(package_dir, tmp_dir=None, log=print) -> dict:
    """Build everything into ``package_dir`` (the openmm_symprk/plugin folder).  Returns the build info."""
    if os.environ.get("SYMPRK_NATIVE", "1").strip().lower() in ("0", "no", "off", "false"):
        raise NativeBuildError("SYMPRK_NATIVE=0: native build disabled by the environment")
    if not sys.platform.startswith("linux"):
        raise NativeBuildError(f"the native build supports Linux only (this is {sys.platform})")
    t0 = time.time()
    out = Path(package_dir).resolve()
    tmp = Path(tmp_dir) if tmp_dir else Path(tempfile.mkdtemp(prefix="symprk-native-"))
    _cxx()  # the compiler first: without one nothing else matters
    omm = locate_openmm()
    swig = find_swig()
    log(f"openmm_symprk native: building against openmm {omm['version']} ({omm['origin']}: {omm['lib']}) "
        f"with {swig}")
    clean(out)
    b = _Builder(omm, out, tmp, log)
    info = {"openmm_version": omm["version"], "openmm_lib": omm["lib"], "openmm_origin": omm["origin"],
            "libraries": {}, "skipped": {}}

    # SWIG runs while the C++ compiles (it only reads the headers).
    swig_out = tmp / "symprk_wrap.cxx"
    swig_cmd = [swig, "-python", "-c++", "-O", "-interface", "symprk_swig_ext", f"-I{omm['include']}",
                f"-I{HERE / 'openmmapi' / 'include'}",
                "-outdir", str(tmp), "-o", str(swig_out), str(HERE / "python" / "symprk.i")]
    swig_proc = subprocess.Popen(swig_cmd, stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)

    strict = ["-Wl,--no-undefined"]  # every symbol of a kernel library resolves at link time
    api = b.lib_dir / "libOpenMMSymPRK.so"
    b.link(b.compile([HERE / "openmmapi" / "src" / "SymPRKIntegrator.cpp",
                      HERE / "serialization" / "src" / "SymPRKIntegratorProxy.cpp"]), api, ["OpenMM"], [omm["lib"]],
           b.rpath_lib, strict)
    info["libraries"]["api"] = api.name
    ref = b.lib_dir / "libOpenMMSymPRKReference.so"
    b.link(b.compile([HERE / "reference" / "src" / "ReferenceSymPRKKernels.cpp",
                      HERE / "reference" / "src" / "ReferenceSymPRKKernelFactory.cpp"]),
           ref, ["OpenMMSymPRK", "OpenMM"], [b.lib_dir, omm["lib"]], b.rpath_lib, strict)
    info["libraries"]["Reference"] = ref.name

    common_src = [HERE / "common" / "src" / "CommonSymPRKKernels.cpp", _embed_kernel_sources(tmp)]
    common_objs = b.compile(common_src)  # platform independent: shared by the OpenCL and CUDA libraries
    ocl_inc = _opencl_include()
    if not (Path(omm["plugins"]) / "libOpenMMOpenCL.so").exists():
        info["skipped"]["OpenCL"] = "the openmm wheel has no OpenCL platform library (plugins/libOpenMMOpenCL.so)"
    elif ocl_inc is None:
        info["skipped"]["OpenCL"] = ("no OpenCL C headers (CL/opencl.h) were found: they come with the build "
                                     "requirement nvidia-cuda-opencl-cu12 on Linux x86_64; elsewhere install "
                                     "them (Debian: opencl-c-headers) or set SYMPRK_OPENCL_INCLUDE, then rebuild")
    else:
        try:
            objs = b.compile([HERE / "opencl" / "src" / "OpenCLSymPRKKernelFactory.cpp"],
                             extra_includes=[ocl_inc, Path(omm["include"]) / "openmm" / "opencl"],
                             extra_flags=["-DCL_TARGET_OPENCL_VERSION=120"])
            ocl = b.lib_dir / "libOpenMMSymPRKOpenCL.so"
            b.link(common_objs + objs, ocl, ["OpenMMSymPRK", "OpenMMOpenCL", "OpenMM"],
                   [b.lib_dir, omm["lib"], omm["plugins"]], b.rpath_lib)
            info["libraries"]["OpenCL"] = ocl.name
        except NativeBuildError as exc:
            info["skipped"]["OpenCL"] = str(exc).splitlines()[0]
            log(f"  OpenCL kernel skipped: {exc}")
    cuda_inc = _cuda_includes()
    if not (Path(omm["include"]) / "openmm" / "cuda" / "CudaContext.h").exists():
        info["skipped"]["CUDA"] = "the openmm wheel ships no CUDA platform headers (openmm/cuda/CudaContext.h)"
    elif cuda_inc is None:
        info["skipped"]["CUDA"] = ("no CUDA headers (cuda.h, crt/host_defines.h) were found: they come with the "
                                   "build requirements nvidia-cuda-runtime-cu12 and nvidia-cuda-nvcc-cu12 on Linux "
                                   "x86_64; elsewhere set CUDA_HOME to a CUDA toolkit and rebuild")
    else:
        # The Common compute classes (ComputeArray, IntegrationUtilities, ...) live in each platform library,
        # here OpenMM's libOpenMMCUDA.so (pip install "openmm_symprk[cuda12]").  It is linked when this build
        # can see it; otherwise those symbols stay undefined and resolve when the package loads this library,
        # which it does only in a process where OpenMM's CUDA platform (and so libOpenMMCUDA.so) is loaded.
        # Nothing else is left undefined (tests/native check the library's symbol table).
        try:
            objs = b.compile([HERE / "cuda" / "src" / "CudaSymPRKKernelFactory.cpp"],
                             extra_includes=cuda_inc + [Path(omm["include"]) / "openmm" / "cuda"])
            cu = b.lib_dir / "libOpenMMSymPRKCUDA.so"
            cuda_lib = Path(omm["plugins"]) / "libOpenMMCUDA.so"
            libs = ["OpenMMSymPRK", "OpenMM"] + (["OpenMMCUDA"] if cuda_lib.exists() else [])
            b.link(common_objs + objs, cu, libs, [b.lib_dir, omm["lib"], omm["plugins"]], b.rpath_lib)
            info["cuda_platform_linked"] = cuda_lib.exists()
            info["libraries"]["CUDA"] = cu.name
        except NativeBuildError as exc:
            info["skipped"]["CUDA"] = str(exc).splitlines()[0]
            log(f"  CUDA kernel skipped: {exc}")

    _, swig_err = swig_proc.communicate()
    if swig_proc.returncode != 0:
        raise NativeBuildError(f"SWIG failed:\n{' '.join(swig_cmd)}\n{swig_err[-4000:]}")
    py_inc = sysconfig.get_paths()["include"]
    ext_suffix = sysconfig.get_config_var("EXT_SUFFIX") or ".so"
    wrap_obj = b.compile([swig_out], extra_includes=[py_inc])
    ext = out / f"symprk_swig_ext{ext_suffix}"
    b.link(wrap_obj, ext, ["OpenMMSymPRK", "OpenMM"], [b.lib_dir, omm["lib"]],
           ["$ORIGIN/lib", "$ORIGIN/../../OpenMM.libs/lib", str(b.lib_dir), omm["lib"]])
    shutil.copyfile(tmp / "symprk_swig.py", out / "symprk_swig.py")
    info["extension"] = ext.name
    info["seconds"] = round(time.time() - t0, 1)
    (out / "_build_info.json").write_text(json.dumps(info, indent=2) + "\n")
    log(f"openmm_symprk native: done in {info['seconds']} s "
        f"(platform kernels: {', '.join(k for k in info['libraries'] if k != 'api')}"
        + "".join(f"; {k} skipped: {v}" for k, v in info["skipped"].items()) + ")")
    return info


def clean(package_dir) -> None:
    """Remove a previous build's outputs from ``package_dir``."""
    out = Path(package_dir)
    for p in [out / "_build_info.json", out / "symprk_swig.py", *out.glob("symprk_swig_ext*.so"),
              *out.glob("_symprk_swig*.so")]:
        if p.exists():
            p.unlink()
    if (out / "lib").exists():
        shutil.rmtree(out / "lib")


if __name__ == "__main__":
    target = Path(sys.argv[1]) if len(sys.argv) > 1 else HERE.parent / "openmm_symprk" / "plugin"
    try:
        build(target, HERE.parent / "build" / "native-tmp")
    except NativeBuildError as e:
        print(f"native build failed: {e}", file=sys.stderr)
        sys.exit(1)
