"""mdakit/metadata.yaml, the MDAKits registry's entry for the package: it parses, holds the keys of the
registry's schema (MDAnalysis/MDAKits utils/mdakit.py, required and optional) with their types, and says what
pyproject.toml says (Python and MDAnalysis versions, the extra that brings MDAnalysis, the package it imports)."""
import importlib
import os
import tomllib

import pytest

yaml = pytest.importorskip("yaml", reason="PyYAML is in the test extra")

REPO = os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__))))
#: The registry's keys: (name, type) required, then optional.
REQUIRED = {"project_name": str, "authors": list, "maintainers": list, "description": str, "keywords": list,
            "license": str, "project_home": str, "python_requires": str, "documentation_home": str,
            "documentation_type": str}
OPTIONAL = {"project_org": str, "community_home": str, "install": list, "import_name": str, "src_install": list,
            "run_tests": list, "test_dependencies": list, "development_status": str, "changelog": str,
            "publications": list, "mdanalysis_requires": str}


@pytest.fixture(scope="module")
def metadata():
    with open(os.path.join(REPO, "mdakit", "metadata.yaml")) as fh:
        return yaml.safe_load(fh)


@pytest.fixture(scope="module")
def project():
    """The [project] table of pyproject.toml (PEP 621 metadata)."""
    with open(os.path.join(REPO, "pyproject.toml"), "rb") as fh:
        return tomllib.load(fh)["project"]


def test_the_registry_keys_with_their_types(metadata):
    assert not set(REQUIRED) - set(metadata), "missing required keys"
    assert not set(metadata) - set(REQUIRED) - set(OPTIONAL), "keys the registry does not know"
    for key, kind in {**REQUIRED, **OPTIONAL}.items():
        if key in metadata:
            value = metadata[key]
            assert isinstance(value, kind) and value, (key, value)
            if kind is list:
                assert all(isinstance(v, str) and v.strip() for v in value), (key, value)
    assert metadata["license"] == "MIT" and metadata["project_name"] == "openmm_symprk"


def test_it_says_what_the_package_metadata_says(metadata, project):
    assert metadata["python_requires"] == project["requires-python"]
    pins = [r for r in project["optional-dependencies"]["analysis"] if r.lower().startswith("mdanalysis")]
    assert pins == [f"MDAnalysis{metadata['mdanalysis_requires']}"]
    assert metadata["install"] == ['pip install "openmm_symprk[analysis]"']  # the extra that brings MDAnalysis
    assert metadata["src_install"] == ['pip install ".[analysis]"']
    assert metadata["test_dependencies"] == ['pip install ".[test]"'] and "test" in project["optional-dependencies"]
    assert project["name"] == metadata["import_name"] == "openmm_symprk"


def test_the_kit_imports_holds_analyses_and_its_tests_exist(metadata):
    """The registry's badge for an analysis kit: AnalysisBase subclasses under import_name."""
    from MDAnalysis.analysis.base import AnalysisBase

    importlib.import_module(metadata["import_name"])
    universe = importlib.import_module(f"{metadata['import_name']}.analysis.universe")
    analyses = [name for name in universe.__all__ if isinstance(getattr(universe, name), type)
                and issubclass(getattr(universe, name), AnalysisBase)]
    assert set(analyses) >= {"SelfDiffusion", "Reorientation", "AngularVelocityCorrelation", "KineticTemperatures",
                             "RadialDistribution"}
    for command in metadata["run_tests"]:
        paths = [word for word in command.split() if word.startswith("tests")]
        assert paths and all(os.path.exists(os.path.join(REPO, p)) for p in paths), command
