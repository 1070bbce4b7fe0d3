"""The fidelity observables are pure numerics: no module of studies/fidelity imports OpenMM."""
import ast
import os

import openmm_symprk.studies.fidelity as fidelity

FOLDER = os.path.dirname(fidelity.__file__)


def test_no_openmm_import_in_the_observables():
    found = []
    for name in sorted(os.listdir(FOLDER)):
        if name.endswith(".py"):
            tree = ast.parse(open(os.path.join(FOLDER, name)).read())
            for node in ast.walk(tree):
                mods = [a.name for a in node.names] if isinstance(node, ast.Import) else (
                    [node.module or ""] if isinstance(node, ast.ImportFrom) and not node.level else [])
                found += [f"{name}: {m}" for m in mods if m.split(".")[0] in ("openmm", "simtk")]
    assert not found, found
    assert len([n for n in os.listdir(FOLDER) if n.endswith(".py")]) >= 7  # the test sees the modules
