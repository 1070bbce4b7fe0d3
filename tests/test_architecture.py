"""The package's layout, checked from the source: layers import downward only, no import cycles (lazy imports
included), no private names imported across modules, the pure numerics never import OpenMM, the library's tests
never import the studies, and no ``--help`` names an issue of the project."""
import argparse
import ast
import os
import subprocess
import sys

import pytest
from helpers import ISSUE_NUMBER

import openmm_symprk

ROOT = os.path.dirname(openmm_symprk.__file__)
#: Layer of each sub-package (a module may import from lower layers and from its own sub-package).
LAYERS = {"support": 0, "methods": 1, "physics": 1, "stats": 1, "plugin": 1, "systems": 2, "integrators": 3,
          "conservation": 4, "rigid": 4, "analysis": 5, "studies": 6, "cli": 7}
PURE = ("support", "methods", "physics", "stats")


def _modules():
    out = {}
    for folder, dirs, files in os.walk(ROOT):
        dirs[:] = [d for d in dirs if not d.startswith((".", "_"))]
        for f in files:
            if f.endswith(".py") and f != "symprk_swig.py":  # the SWIG-generated wrapper is a build output
                path = os.path.join(folder, f)
                rel = os.path.relpath(path, os.path.dirname(ROOT))[:-3].replace(os.sep, ".")
                out[rel[:-len(".__init__")] if rel.endswith(".__init__") else rel] = path
    return out


MODULES = _modules()


def _imports(name, path):
    """(target module, imported names, lazy?) for every import of the package inside ``name``."""
    tree = ast.parse(open(path, encoding="utf-8").read())
    is_pkg = path.endswith("__init__.py")
    top_level = {id(n) for n in tree.body}
    found = []
    for node in ast.walk(tree):
        if isinstance(node, ast.ImportFrom):
            if node.level:
                base = name.split(".") if is_pkg else name.split(".")[:-1]
                base = base[:len(base) - node.level + 1]
                target = ".".join(base + ([node.module] if node.module else []))
            else:
                target = node.module or ""
            if target.split(".")[0] == "openmm_symprk":
                for alias in node.names:
                    full = f"{target}.{alias.name}"
                    found.append((full if full in MODULES else target, alias.name, id(node) not in top_level))
        elif isinstance(node, ast.Import):
            for alias in node.names:
                if alias.name.split(".")[0] == "openmm_symprk":
                    found.append((alias.name, None, id(node) not in top_level))
    return found


def _layer(module):
    parts = module.split(".")
    return LAYERS.get(parts[1]) if len(parts) > 1 else None


def test_layers_import_downward_only():
    wrong = []
    for name, path in MODULES.items():
        mine = _layer(name)
        if mine is None:
            continue  # the package's facade, openmm_symprk/__init__.py
        for target, _, _ in _imports(name, path):
            theirs = _layer(target)
            if target == "openmm_symprk" and not name.startswith("openmm_symprk.cli"):
                wrong.append(f"{name} imports the package facade")
            elif theirs is not None and theirs >= mine and target.split(".")[1] != name.split(".")[1]:
                wrong.append(f"{name} (layer {mine}) imports {target} (layer {theirs})")
    assert not wrong, "\n".join(wrong)


def test_no_import_cycles_lazy_imports_included():
    graph = {m: set() for m in MODULES}
    for name, path in MODULES.items():
        for target, _, _ in _imports(name, path):
            if target in MODULES and target != name and not name.startswith(target + "."):
                graph[name].add(target)
    index, low, stack, on, cycles = {}, {}, [], set(), []

    def visit(v):
        index[v] = low[v] = len(index)
        stack.append(v)
        on.add(v)
        for w in graph[v]:
            if w not in index:
                visit(w)
                low[v] = min(low[v], low[w])
            elif w in on:
                low[v] = min(low[v], index[w])
        if low[v] == index[v]:
            comp = []
            while True:
                w = stack.pop()
                on.discard(w)
                comp.append(w)
                if w == v:
                    break
            if len(comp) > 1:
                cycles.append(sorted(comp))

    sys.setrecursionlimit(10000)
    for v in graph:
        if v not in index:
            visit(v)
    assert not cycles, cycles


def test_no_private_names_imported_across_modules():
    private = [f"{name} <- {target}.{alias}" for name, path in MODULES.items()
               for target, alias, _ in _imports(name, path)
               if alias and alias.startswith("_") and not alias.startswith("__") and target != name]
    assert not private, private


@pytest.mark.parametrize("package", PURE)
def test_pure_numerics_do_not_import_openmm(package):
    for name, path in MODULES.items():
        if name.split(".")[1:2] == [package]:
            tree = ast.parse(open(path, encoding="utf-8").read())
            for node in ast.walk(tree):
                mods = [a.name for a in node.names] if isinstance(node, ast.Import) else (
                    [node.module or ""] if isinstance(node, ast.ImportFrom) and not node.level else [])
                assert not any(m.split(".")[0] in ("openmm", "simtk") for m in mods), (name, mods)
    # and at run time: importing the package's pure layers loads no OpenMM module (the parent package is a bare
    # namespace here, so that its __init__, which loads the integrators, does not run)
    code = (f"import sys, types; sys.modules['openmm'] = None\n"
            f"parent = types.ModuleType('openmm_symprk'); parent.__path__ = [{ROOT!r}]\n"
            f"sys.modules['openmm_symprk'] = parent\n"
            f"import openmm_symprk.{package}\n"
            f"assert not [m for m in sys.modules if m.startswith('openmm.')], 'OpenMM loaded'\n")
    res = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True)
    assert res.returncode == 0, res.stderr[-2000:]


#: The modules at the package root: the facade and the command (with its frame).
ROOT_MODULES = ["__init__.py", "cli.py"]


def test_few_modules_at_the_package_root():
    root = sorted(f for f in os.listdir(ROOT) if f.endswith(".py"))
    assert root == ROOT_MODULES, root


def _study(module):
    """The study a module of openmm_symprk.studies belongs to ("bench", "platforms", "demo", ...; "core" for the
    machinery they share), or None outside the studies."""
    parts = module.split(".")
    return parts[2] if len(parts) > 2 and parts[1] == "studies" else None


def test_no_study_imports_another():
    """openmm_symprk/studies/<x>/ (or studies/<x>.py) imports studies/core and the lower layers, never studies/<y>/:
    what two studies share lives in studies/core."""
    wrong = [f"{name} imports {target}" for name, path in MODULES.items() for target, _, _ in _imports(name, path)
             if _study(name) not in (None, "core") and _study(target) not in (None, "core", _study(name))]
    assert not wrong, "\n".join(wrong)
    # the machinery imports no study
    assert not [t for n, p in MODULES.items() if _study(n) == "core" for t, _, _ in _imports(n, p)
                if _study(t) not in (None, "core")]


def test_the_library_does_not_reach_into_the_studies():
    """Below the studies (and in the command, but for its table of sub-commands, which names them by module path)
    nothing imports openmm_symprk.studies: studies-only code lives in studies/."""
    wrong = [f"{name} imports {target}" for name, path in MODULES.items() if _layer(name) is not None
             and _layer(name) < LAYERS["studies"] for target, _, _ in _imports(name, path)
             if target.startswith("openmm_symprk.studies")]
    assert not wrong, wrong
#: The test-suite's folder; tests/studies/ tests the studies, everything else the library.
TESTS = os.path.dirname(os.path.abspath(__file__))


def _study_imports(tree) -> list:
    """(line, module) of every import of openmm_symprk.studies in ``tree``: import statements, and
    ``import_module("openmm_symprk.studies...")``."""
    found = []
    for node in ast.walk(tree):
        if isinstance(node, ast.ImportFrom) and not node.level:
            mods = [f"{node.module}.{a.name}" for a in node.names] if node.module == "openmm_symprk" else [node.module]
        elif isinstance(node, ast.Import):
            mods = [a.name for a in node.names]
        elif isinstance(node, ast.Call) and getattr(node.func, "attr", getattr(node.func, "id", None)) == \
                "import_module" and node.args and isinstance(node.args[0], ast.Constant):
            mods = [node.args[0].value]
        else:
            continue
        found += [(node.lineno, m) for m in mods if isinstance(m, str) and
                  (m == "openmm_symprk.studies" or m.startswith("openmm_symprk.studies."))]
    return found


def test_the_library_tests_do_not_import_the_studies():
    """A test of the library (under tests/, outside tests/studies/) imports no study, so that a study's change never
    breaks it: what a library test shares with a study lives in the library (or in the tests' helpers)."""
    wrong, read = [], 0
    for folder, dirs, files in os.walk(TESTS):
        dirs[:] = [d for d in dirs if not d.startswith((".", "_")) and
                   os.path.relpath(os.path.join(folder, d), TESTS) != "studies"]
        for f in files:
            if f.endswith(".py"):
                path = os.path.join(folder, f)
                read += 1
                wrong += [f"{os.path.relpath(path, TESTS)}:{line} imports {m}"
                          for line, m in _study_imports(ast.parse(open(path, encoding="utf-8").read()))]
    assert not wrong, "\n".join(wrong)
    assert read > 50  # the walk saw the library's tests
    # and the rule sees an import where there is one
    assert _study_imports(ast.parse("from openmm_symprk.studies.nvt.known import run\nfrom openmm_symprk import studies"
                                    "\nimportlib.import_module('openmm_symprk.studies.bench')")) == \
        [(1, "openmm_symprk.studies.nvt.known"), (2, "openmm_symprk.studies"), (3, "openmm_symprk.studies.bench")]


def _parsers() -> list:
    """``symprk``'s parser and every sub-command's, their own sub-commands' included (``symprk nvt cost`` ...)."""
    from importlib import import_module

    from openmm_symprk.cli import COMMANDS, build_parser

    todo = [build_parser()] + [import_module(c.module).build_parser(f"symprk {n}") for n, c in COMMANDS.items()]
    out = []
    while todo:
        p = todo.pop(0)
        out.append(p)
        todo += [sub for a in p._actions if isinstance(a, argparse._SubParsersAction) for sub in a.choices.values()]
    return out


def test_no_issue_number_in_any_help():
    """``--help`` speaks to users: no sub-command's help, option, choice (a preset's name) or default names an issue
    of the project."""
    from openmm_symprk.cli import COMMANDS

    parsers = _parsers()
    found = [f"{p.prog}: ...{p.format_help()[max(0, m.start() - 40):m.end() + 20]!r}..." for p in parsers
             for m in ISSUE_NUMBER.finditer(p.format_help())]
    assert not found, "\n".join(found)
    assert len(parsers) > len(COMMANDS) + 1 and {"symprk nvt cost", "symprk nvt known"} <= {p.prog for p in parsers}
    assert all(ISSUE_NUMBER.search(t) for t in ("the rows that decide issue 26's answer", "--preset issue26",
                                                "(issues 33 and 36)", "Issue #35"))


#: The modules that build or run the step: they execute the resolved method's sub-steps, thermostat events included,
#: and decide nothing of where the events go (openmm_symprk.methods.resolved does).
STEP_RUNNERS = ("integrators.program", "integrators.thermostat_program", "integrators.custom_backend",
                "integrators.native_backend", "integrators.backend", "integrators.base")


def _schedule_decisions(tree) -> list:
    """(line, what) of every place in ``tree`` that decides a thermostat schedule: a comparison with a placement's
    name ("ends", "middle"), a sub-step built (``Substep(...)``), a placement sequence made (``with_thermostat``,
    ``centre``, ``best_position``), or the centre step of an interval worked out (a floor division by 2)."""
    from openmm_symprk.methods.placement import POSITIONS

    found = []
    for node in ast.walk(tree):
        if isinstance(node, ast.Compare):
            names = [c.value for c in [node.left, *node.comparators] if isinstance(c, ast.Constant)]
            if any(n in POSITIONS for n in names):
                found.append((node.lineno, f"compares with the placement {names}"))
        elif isinstance(node, ast.Call):
            name = getattr(node.func, "id", getattr(node.func, "attr", None))
            if name in ("Substep", "with_thermostat", "centre", "best_position"):
                found.append((node.lineno, f"calls {name}"))
        elif isinstance(node, ast.BinOp) and isinstance(node.op, ast.FloorDiv) and \
                isinstance(node.right, ast.Constant) and node.right.value == 2:
            found.append((node.lineno, "works out a centre step (// 2)"))
    return found


def test_nothing_under_integrators_decides_a_thermostat_schedule():
    """Where the thermostat's events sit, their fractions and their steps of the interval are resolve's
    (methods/resolved.py); the CustomIntegrator compiler and the backends only execute the sub-steps."""
    wrong = []
    for short in STEP_RUNNERS:
        name = "openmm_symprk." + short
        for line, what in _schedule_decisions(ast.parse(open(MODULES[name]).read())):
            wrong.append(f"{MODULES[name]}:{line}: {what}")
    assert not wrong, "\n".join(wrong)
    # and the rule sees a decision where there is one
    assert _schedule_decisions(ast.parse("if position == 'middle': k = (n - 1) // 2"))


#: The calls that walk the interpreter's heap to find objects.
HEAP_SCANS = ("get_objects", "get_referrers", "get_referents")


def _heap_scans(tree) -> list:
    """(line, call) of every ``gc.get_objects`` (or ``get_referrers``, ``get_referents``) in ``tree``."""
    return [(node.lineno, f"gc.{node.func.attr}") for node in ast.walk(tree)
            if isinstance(node, ast.Call) and isinstance(node.func, ast.Attribute) and node.func.attr in HEAP_SCANS
            and getattr(node.func.value, "id", None) == "gc"]


def test_nothing_in_the_package_scans_the_python_heap():
    """No module finds an object by walking the Python heap (the integrators once found their Context so, at a cost
    that grows with everything the process holds): what an object needs, it is given or keeps."""
    wrong = [f"{path}:{line}: {call}" for name, path in MODULES.items()
             for line, call in _heap_scans(ast.parse(open(path, encoding="utf-8").read()))]
    assert not wrong, "\n".join(wrong)
    # and the rule sees a scan where there is one
    assert _heap_scans(ast.parse("import gc\nfound = [o for o in gc.get_objects() if o]"))
