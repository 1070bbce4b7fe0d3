"""The fidelity study's pure side is pure numerics: no module directly in studies/fidelity (the rows' description,
the extrapolation, the report) nor in openmm_symprk/analysis (the observables' kernels) imports OpenMM; the
study's OpenMM side is the sub-package studies/fidelity/simulation."""
import ast
import os

import pytest

import openmm_symprk.analysis as analysis
import openmm_symprk.studies.fidelity as fidelity


@pytest.mark.parametrize("folder", [os.path.dirname(fidelity.__file__), os.path.dirname(analysis.__file__)])
def test_no_openmm_import_in_the_observables(folder):
    found = []
    for name in sorted(os.listdir(folder)):
        if name.endswith(".py"):
            tree = ast.parse(open(os.path.join(folder, name), encoding="utf-8").read())
            for node in ast.walk(tree):
                mods = [a.name for a in node.names] if isinstance(node, ast.Import) else (
                    [node.module or ""] if isinstance(node, ast.ImportFrom) and not node.level else [])
                found += [f"{name}: {m}" for m in mods if m.split(".")[0] in ("openmm", "simtk")]
    assert not found, found
    assert len([n for n in os.listdir(folder) if n.endswith(".py")]) >= 5  # the test sees the modules
