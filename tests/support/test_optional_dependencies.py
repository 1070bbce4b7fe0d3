"""Optional dependencies: the core (package, integrators, ``symprk demo/methods/info``) works with none of them
installed, and every feature that needs one says which package is missing and which extra installs it."""
import ast
import json
import os
import re
import subprocess
import sys
import textwrap

import pytest

import openmm_symprk
from openmm_symprk.support import EXTRAS, MissingDependencyError, require
from openmm_symprk.support.optional import PACKAGES

PACKAGE_DIR = os.path.dirname(openmm_symprk.__file__)
REPO = os.path.dirname(PACKAGE_DIR)
OPTIONAL = sorted(set(PACKAGES))

#: Installed as sitecustomize, it makes the packages named by $SYMPRK_TEST_ABSENT look absent to the interpreter.
BLOCKER = textwrap.dedent("""
    import importlib.abc, os, sys

    class _Absent(importlib.abc.MetaPathFinder):
        absent = set(os.environ["SYMPRK_TEST_ABSENT"].split(","))

        def find_spec(self, name, path, target=None):
            if name.split(".")[0] in self.absent:
                raise ModuleNotFoundError(f"No module named {name!r}", name=name)

    sys.meta_path.insert(0, _Absent())
""")


def _run_without_extras(tmp_path, args, absent=OPTIONAL):
    """Run ``python args`` from the repository root with the packages ``absent`` (all optional ones) blocked."""
    (tmp_path / "sitecustomize.py").write_text(BLOCKER)
    env = dict(os.environ, PYTHONPATH=os.pathsep.join([str(tmp_path), REPO]), SYMPRK_TEST_ABSENT=",".join(absent))
    return subprocess.run([sys.executable, *args], cwd=REPO, env=env, capture_output=True, text=True, timeout=300)


# -- the helper -------------------------------------------------------------------------------------------------------
def test_require_returns_the_module():
    import scipy.special

    assert require("scipy.special", "analysis", "a test") is scipy.special


def test_a_missing_package_names_feature_package_and_extra(monkeypatch):
    monkeypatch.setitem(sys.modules, "tqdm", None)  # "import tqdm" now fails as if it were not installed
    with pytest.raises(MissingDependencyError) as info:
        require("tqdm", "studies", "the progress bar of a test")
    msg = str(info.value)
    assert msg.startswith("the progress bar of a test needs tqdm, which is not installed")
    assert "pip install 'openmm_symprk[studies]'" in msg
    assert isinstance(info.value, ImportError)  # callers that fall back on ImportError keep working
    assert (info.value.package, info.value.extra) == ("tqdm", "studies")


def test_dask_is_named_by_its_pip_requirement(monkeypatch):
    for name in ["dask", *(m for m in list(sys.modules) if m.startswith("dask."))]:
        monkeypatch.setitem(sys.modules, name, None)  # as if absent, even after another test imported it
    with pytest.raises(MissingDependencyError, match=r"needs dask\[distributed\].*openmm_symprk\[cluster\]"):
        require("dask.distributed", "cluster", "cluster runs")


def test_an_installed_but_broken_package_reports_why(tmp_path, monkeypatch):
    broken = tmp_path / "pymbar"
    broken.mkdir()
    (broken / "__init__.py").write_text("import symprk_no_such_dependency_xyz\n")
    monkeypatch.syspath_prepend(str(tmp_path))
    for name in [m for m in sys.modules if m.split(".")[0] == "pymbar"]:
        monkeypatch.delitem(sys.modules, name)
    with pytest.raises(MissingDependencyError) as info:
        require("pymbar", "studies", "statistics")
    msg = str(info.value)
    assert "which does not import here" in msg and "symprk_no_such_dependency_xyz" in msg, msg
    assert "openmm_symprk[studies]" in msg


@pytest.mark.parametrize("module, extra, message", [
    ("numpy", "analysis", "'numpy' is not an optional dependency"),
    ("pymbar", "analysis", "the extra 'analysis' does not install pymbar (it is in 'studies', 'all')"),
    ("MDAnalysis", "analysys", "the extra 'analysys' does not install MDAnalysis"),
])
def test_a_wrong_call_is_a_value_error(module, extra, message):
    with pytest.raises(ValueError, match=re.escape(message)):
        require(module, extra, "x")


def test_all_is_analysis_and_studies():
    assert set(EXTRAS["all"]) == set(EXTRAS["analysis"]) | set(EXTRAS["studies"])
    assert set(EXTRAS) == {"analysis", "studies", "cluster", "all"}


# -- the package goes through the helper -------------------------------------------------------------------------------
def _sources():
    for folder, dirs, files in os.walk(PACKAGE_DIR):
        dirs[:] = [d for d in dirs if not d.startswith((".", "_"))]
        for f in files:
            if f.endswith(".py") and f != "symprk_swig.py":
                path = os.path.join(folder, f)
                yield os.path.relpath(path, REPO), ast.parse(open(path, encoding="utf-8").read())


def test_optional_packages_are_imported_only_through_require():
    direct, calls = [], 0
    for rel, tree in _sources():
        for node in ast.walk(tree):
            names = ([a.name for a in node.names] if isinstance(node, ast.Import) else
                     [node.module or ""] if isinstance(node, ast.ImportFrom) and not node.level else [])
            direct += [f"{rel}:{node.lineno} imports {n}" for n in names if n.split(".")[0] in PACKAGES]
            if isinstance(node, ast.Call) and getattr(node.func, "id", None) == "require":
                calls += 1
                args = [a.value if isinstance(a, ast.Constant) else None for a in node.args]
                # the module and the extra written out (checked against EXTRAS below); what needs it may be passed on
                # by a helper that is called with it (studies/core/charts.py)
                assert len(args) == 3 and all(isinstance(a, str) and a for a in args[:2]), (rel, node.lineno)
                assert args[2] is None or (isinstance(args[2], str) and args[2]), (rel, node.lineno)
                module, extra, _ = args
                assert PACKAGES[module.split(".")[0]] in EXTRAS[extra], (rel, node.lineno, module, extra)
    assert not direct, "\n".join(direct)
    assert calls >= 10  # the scan sees the package's calls (it would pass vacuously on a wrong folder)


def test_extras_agree_with_pyproject():
    """pyproject.toml's extras install the packages EXTRAS says they do (the error messages name those extras)."""
    import tomllib

    path = os.path.join(REPO, "pyproject.toml")
    if not os.path.exists(path):
        pytest.skip("not a source checkout (pyproject.toml absent)")
    with open(path, "rb") as fh:
        extras = tomllib.load(fh)["project"]["optional-dependencies"]

    def names(reqs):
        return {re.split(r"\s*[<>=!~;]", r)[0].strip().lower() for r in reqs}

    for extra, packages in EXTRAS.items():
        assert names(extras[extra]) == {p.lower() for p in packages}, (extra, extras[extra], packages)


# -- with none of the optional packages installed --------------------------------------------------------------------
CORE = """
import numpy as np, openmm as mm, openmm.unit as unit
import openmm_symprk
from openmm_symprk import SymplecticIntegrator
try:
    import scipy
except ImportError:
    pass
else:
    raise SystemExit("the blocker does not work")
system = mm.System()
for _ in range(3):
    system.addParticle(12.0)
bonds = mm.HarmonicBondForce()
bonds.addBond(0, 1, 0.15, 2.0e5)
bonds.addBond(1, 2, 0.15, 2.0e5)
system.addForce(bonds)
system.addConstraint(0, 2, 0.25)
integrator = SymplecticIntegrator(1.0 * unit.femtoseconds, "yoshida-4", system=system)
context = mm.Context(system, integrator, mm.Platform.getPlatformByName("Reference"))
context.setPositions(np.array([[0, 0, 0], [0.16, 0.05, 0], [0.25, 0, 0]]))
context.setVelocitiesToTemperature(300 * unit.kelvin, 1)
def energy():
    s = context.getState(getEnergy=True)
    return (s.getPotentialEnergy() + s.getKineticEnergy()).value_in_unit(unit.kilojoule_per_mole)
e0 = energy()
integrator.step(200)
x = context.getState(getPositions=True).getPositions(asNumpy=True).value_in_unit(unit.nanometer)
print(json.dumps({"drift": abs(energy() - e0), "e0": e0, "moved": float(abs(x[1] - [0.16, 0.05, 0]).max()),
                  "constraint": float(np.linalg.norm(x[2] - x[0]))}))
"""


def test_the_core_works_without_optional_packages(tmp_path):
    res = _run_without_extras(tmp_path, ["-c", "import json, sys\n" + CORE])
    assert res.returncode == 0, res.stderr[-3000:]
    out = json.loads(res.stdout.strip().splitlines()[-1])
    assert out["moved"] > 1e-3 and out["drift"] < 1e-3 * abs(out["e0"]), out  # it stepped, conserving energy
    assert out["constraint"] == pytest.approx(0.25, rel=1e-5), out  # within the default constraint tolerance


@pytest.mark.parametrize("argv, expect", [
    (["methods"], "yoshida-4"),
    (["info"], "catalogue:"),
    (["demo", "--waters", "4", "--steps", "20"], "yoshida-4"),
])
def test_the_core_commands_work_without_optional_packages(tmp_path, argv, expect):
    res = _run_without_extras(tmp_path, ["-m", "openmm_symprk.cli", *argv])
    assert res.returncode == 0, res.stderr[-3000:]
    assert expect in res.stdout


#: feature -> (code run with its package blocked and all others present, that package, the extra its error names)
FEATURES = {
    "conservation.analysis": ("import openmm_symprk.conservation.analysis", "MDAnalysis", "analysis"),
    "VelocityTRRReporter": ("from openmm_symprk.conservation import VelocityTRRReporter\n"
                            "VelocityTRRReporter(os.path.join(TMP, 'x.trr'), 10)", "MDAnalysis", "analysis"),
    "rigid exact solution": ("from openmm_symprk.rigid.lie_poisson import exact_solution\n"
                             "exact_solution([0.4, 1.1, -0.8], [1.8, 0.7, 1.3], [0.5])", "scipy", "analysis"),
    "stability_interval": ("from openmm_symprk.methods.stability import stability_interval\n"
                           "stability_interval('verlet')", "scipy", "analysis"),
    "bench charts": ("import openmm_symprk.studies.bench.charts", "matplotlib", "studies"),
    "bench toys": ("import openmm_symprk.studies.core.toys", "scipy", "studies"),
    "equipartition chart": ("from openmm_symprk.studies.equipartition.report import chart\n"
                            "chart({'models': {}}, os.path.join(TMP, 'x.png'))", "matplotlib", "studies"),
    "dask executor": ("from openmm_symprk.studies.core.executors import DaskExecutor\n"
                      "DaskExecutor(print, {}, 'tcp://127.0.0.1:1')", "dask[distributed]", "cluster"),
    "progress bar": ("from openmm_symprk.studies.core.study import progress_bar\n"
                     "progress_bar(3, 'runs')", "tqdm", "studies"),
    "statistics": ("from openmm_symprk.stats import statistical_inefficiency\n"
                   "statistical_inefficiency(np.sin(np.arange(100.0)))", "pymbar", "studies"),
}
PROBE = """
import json, os, sys
import numpy as np
TMP = sys.argv[1]
results = {}
for name, code in json.loads(sys.argv[2]).items():
    try:
        exec(code)
        results[name] = "no error"
    except Exception as exc:
        results[name] = f"{type(exc).__name__}: {exc}"
print(json.dumps(results))
"""


@pytest.fixture(scope="module")
def feature_errors(tmp_path_factory):
    """The error of each feature, run in one interpreter per package with only that package blocked."""
    errors = {}
    for package in sorted({p for _, p, _ in FEATURES.values()}):
        tmp = tmp_path_factory.mktemp("extras")
        cases = {k: code for k, (code, p, _) in FEATURES.items() if p == package}
        top = [m for m, pip in PACKAGES.items() if pip == package]
        res = _run_without_extras(tmp, ["-c", PROBE, str(tmp), json.dumps(cases)], absent=top)
        assert res.returncode == 0, res.stderr[-3000:]
        errors.update(json.loads(res.stdout.strip().splitlines()[-1]))
    return errors


@pytest.mark.parametrize("feature", sorted(FEATURES))
def test_each_optional_feature_names_its_extra(feature_errors, feature):
    _, package, extra = FEATURES[feature]
    msg = feature_errors[feature]
    assert msg.startswith("MissingDependencyError: "), msg
    assert f"needs {package}, which is not installed: pip install 'openmm_symprk[{extra}]'" in msg, msg


def test_a_study_command_without_its_extra_fails_in_one_line(tmp_path):
    res = _run_without_extras(tmp_path, ["-m", "openmm_symprk.cli", "bench", "--quick", "--scenes", "harmonic",
                                         "--no-stability", "--no-charts", "--no-progress", "--workers", "1",
                                         "--out", str(tmp_path / "out")])
    assert res.returncode == 2
    assert res.stderr.strip().count("\n") == 0, res.stderr  # one line, no traceback
    # the first of the extra's packages the command reaches (tqdm: a study checks it before any work; scipy: the bench)
    assert re.search(r"needs (tqdm|scipy), which is not installed", res.stderr), res.stderr
    assert "pip install 'openmm_symprk[studies]'" in res.stderr, res.stderr


def test_a_broken_submodule_is_not_called_absent(monkeypatch):
    """scipy installed, one of its compiled parts missing: the error says what failed, not "not installed"."""
    import importlib

    real = importlib.import_module

    def broken(name, package=None):
        if name == "scipy.special":
            raise ModuleNotFoundError("No module named 'scipy.special._ufuncs'", name="scipy.special._ufuncs")
        return real(name, package)

    monkeypatch.setattr(importlib, "import_module", broken)
    with pytest.raises(MissingDependencyError, match=r"needs scipy, which does not import here \(ModuleNotFound"):
        require("scipy.special", "analysis", "elliptic functions")
