"""The native build (setup.py driving platforms/CMakeLists.txt) and what it installs.

* the installed libraries keep only run paths relative to their own folder ($ORIGIN), none of the build machine;
* the C++ tests CMake builds (serialization round trip, one Reference step against a hand computation) pass;
* a failed or disabled build leaves the reason in _build_error.txt and no half-installed plugin;
* one version, the extras the import guards name.

The moved-wheel case (a wheel installed into another environment, source and build folders deleted, still
loading its kernels) is a CI step: .ci/run.
"""
import glob
import importlib.util
import os
import subprocess
import sys
import sysconfig

import pytest

import openmm_symprk
from openmm_symprk import plugin

REPO = os.path.abspath(os.path.join(os.path.dirname(__file__), "..", ".."))
SETUP = os.path.join(REPO, "setup.py")
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


# -- packaging ------------------------------------------------------------------------------------------------------
def test_one_version():
    assert _setup_module().version() == openmm_symprk.__version__


def test_extras():
    """The extras the package's import guards name, and the test extra holds everything the suite uses."""
    extras = _setup_module().EXTRAS
    assert {"analysis", "studies", "cluster", "all", "test", "cuda12", "docs"} <= set(extras)
    names = {k: {r.split(">")[0].split("<")[0].split("[")[0].lower() for r in v} for k, v in extras.items()}
    assert names["analysis"] == {"mdanalysis", "scipy", "tqdm"}
    assert names["studies"] == {"matplotlib", "tqdm", "pymbar", "scipy", "mdanalysis"}
    assert names["all"] == names["analysis"] | names["studies"]
    # the docs' API reference imports every module, so the docs extra holds all of `all`
    assert names["docs"] == {"sphinx", "myst-parser", "furo"} | names["all"]
    # the suite cross-checks the analyses against MDAnalysis' test files and the MDAKits computing the same
    cross_checks = {"mdanalysistests", "waterdynamics", "transport-analysis", "tidynamics"}
    assert names["test"] == {"pytest", "pyelftools", "pyyaml"} | names["all"] | names["cluster"] | cross_checks
