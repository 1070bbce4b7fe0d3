"""What docs/analysis.md tells a reader to install holds what its example and the cross-checks it describes import:
the example's imports come with the command on its "Install:" line, the cross-checks' (tests/analysis/) with the
command of its "Cross-checks" section (the extras read from pyproject.toml)."""
import ast
import glob
import importlib.metadata
import os
import re
import sys
import tomllib

import pytest

from test_docs import python_blocks

REPO = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
DOC = os.path.join(REPO, "docs", "analysis.md")


def _norm(name: str) -> str:
    return re.sub(r"[-_.]+", "-", name).lower()


def _requirement(req: str) -> str:
    return _norm(re.split(r"\s*[<>=!~;\[]", req)[0].strip())


@pytest.fixture(scope="module")
def project():
    path = os.path.join(REPO, "pyproject.toml")
    if not os.path.exists(path):
        pytest.skip("not a source checkout (pyproject.toml absent)")
    with open(path, "rb") as fh:
        return tomllib.load(fh)["project"]


def _installs(command: str, project) -> set:
    """The distributions `pip install ...` installs (the package's core and named extras, and other packages)."""
    extras = project["optional-dependencies"]
    out = set()
    for word in command.split()[2:]:
        word = word.strip("'\"")
        m = re.fullmatch(r"(?:openmm_symprk|\.)\[([\w,-]+)\]", word)
        if m:
            out |= {_requirement(r) for r in project["dependencies"]}
            for extra in m.group(1).split(","):
                out |= {_requirement(r) for r in extras[extra]}
        elif not word.startswith("-"):
            out.add(_requirement(word))
    return out


def _needed(sources) -> set:
    """The distributions ``sources`` (Python texts) import or importorskip, less the standard library, the package
    itself and the test-suite's own modules."""
    tops = set()
    for text in sources:
        for node in ast.walk(ast.parse(text)):
            if isinstance(node, ast.Import):
                tops |= {a.name.split(".")[0] for a in node.names}
            elif isinstance(node, ast.ImportFrom) and not node.level:
                tops.add(node.module.split(".")[0])
            elif isinstance(node, ast.Call) and getattr(node.func, "attr", None) == "importorskip":
                tops.add(node.args[0].value.split(".")[0])
    local = {os.path.splitext(os.path.basename(p))[0] for p in glob.glob(os.path.join(REPO, "tests", "*.py"))}
    tops -= set(sys.stdlib_module_names) | local | {"openmm_symprk"}
    dists = importlib.metadata.packages_distributions()
    missing = sorted(t for t in tops if t not in dists)
    if missing:
        pytest.skip(f"not installed here, so their distributions are unknown: {missing}")
    return {_norm(dists[t][0]) for t in tops}


def _command(text: str) -> str:
    m = re.search(r"`(pip install [^`]+)`", text)
    assert m, f"no `pip install ...` in: {text[:200]}"
    return m.group(1)


def test_the_example_imports_what_the_install_line_installs(project):
    with open(DOC, encoding="utf-8") as fh:
        text = fh.read()
    line = text[text.index("Install:"):].split("\n\n")[0]
    commands = re.findall(r"`(pip install [^`]+)`", line)
    installed = set().union(*(_installs(c, project) for c in commands))
    needed = _needed([code for code, _ in python_blocks(DOC)])
    assert needed <= installed, f"docs/analysis.md's example imports {sorted(needed - installed)}, which " \
                                f"{commands} do not install"


def test_the_cross_checks_import_what_their_section_says_to_install(project):
    with open(DOC, encoding="utf-8") as fh:
        text = fh.read()
    section = text[text.index("## Cross-checks"):]
    section = section[:section.index("\n## ", 3)]
    installed = _installs(_command(section), project)
    sources = [open(p, encoding="utf-8").read() for p in sorted(glob.glob(os.path.join(REPO, "tests", "analysis", "*.py")))]
    needed = _needed(sources)
    assert {"pytest", "tidynamics", "mdanalysistests"} <= needed  # the scan sees the cross-checks' imports
    assert needed <= installed, f"the cross-checks import {sorted(needed - installed)}, which " \
                                f"{_command(section)!r} does not install"
