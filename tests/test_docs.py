"""Every Python code block of README.md and docs/*.md runs as written, and every example script runs.

A document's blocks run in order in one namespace, in a scratch folder, like a script that copies them
one after the other; a block preceded by ``<!-- docs-test: skip (reason) -->`` is left out (none is today).
The examples run in a subprocess with ``--quick``.  The documentation site (docs/conf.py) builds with warnings as
errors and every cross-reference checked, where Sphinx is installed (the ``docs`` extra; .ci/run builds it too).
"""
import glob
import importlib.util
import os
import re
import subprocess
import sys
import warnings

import pytest
from helpers import ISSUE_NUMBER

REPO = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
DOCS = [os.path.join(REPO, "README.md")] + sorted(glob.glob(os.path.join(REPO, "docs", "*.md")))
EXAMPLES = sorted(glob.glob(os.path.join(REPO, "examples", "*.py")))
BLOCK = re.compile(r"(<!-- docs-test: skip[^>]*-->\s*\n)?```python\n(.*?)```", re.S)


def python_blocks(path):
    with open(path, encoding="utf-8") as fh:
        text = fh.read()
    return [(m.group(2), bool(m.group(1))) for m in BLOCK.finditer(text)]


#: Pages whose headings still name issues of the project, until they are rewritten: each is expected to fail the rule
#: below, and passing it fails the test, so that it leaves this list then (none now).
HEADINGS_PENDING = set()
FENCE = re.compile(r"^```.*?^```", re.S | re.M)


def headings(text: str) -> list:
    """The Markdown headings of ``text``, fenced code blocks left out (a shell comment is not a heading)."""
    return re.findall(r"^#{1,6} .*$", FENCE.sub("", text), re.M)


@pytest.mark.parametrize("path", [pytest.param(p, marks=pytest.mark.xfail(strict=True, reason="to be rewritten"))
                                  if os.path.relpath(p, REPO) in HEADINGS_PENDING else p for p in DOCS],
                         ids=lambda p: os.path.relpath(p, REPO))
def test_no_heading_names_an_issue(path):
    """README and the docs lead with what is true now, named by what it is; the project's history (which issue asked
    for what) is the CHANGELOG's."""
    with open(path, encoding="utf-8") as fh:
        found = [h for h in headings(fh.read()) if ISSUE_NUMBER.search(h)]
    assert not found, found
    assert headings("# A\n```bash\n# issue 26\n```\n## Issue 35: B") == ["# A", "## Issue 35: B"]


def test_the_docs_are_found():
    assert os.path.exists(DOCS[0]) and len(DOCS) >= 5, DOCS
    assert sum(len(python_blocks(p)) for p in DOCS) >= 8


@pytest.mark.parametrize("path", DOCS, ids=lambda p: os.path.relpath(p, REPO))
def test_python_blocks_run_as_written(path, tmp_path, monkeypatch):
    blocks = python_blocks(path)
    if not blocks:
        pytest.skip("no Python blocks")
    monkeypatch.chdir(tmp_path)
    namespace = {"__name__": "__docs__"}
    for i, (code, skip) in enumerate(blocks):
        if skip:
            continue
        with warnings.catch_warnings():
            warnings.simplefilter("ignore")
            try:
                exec(compile(code, f"{os.path.basename(path)}, block {i + 1}", "exec"), namespace)
            except Exception as exc:
                raise AssertionError(f"{os.path.relpath(path, REPO)}, Python block {i + 1} fails: "
                                     f"{type(exc).__name__}: {exc}\n{code}") from exc


@pytest.mark.parametrize("script", EXAMPLES, ids=os.path.basename)
def test_examples_run(script, tmp_path):
    res = subprocess.run([sys.executable, script, "--quick"], capture_output=True, text=True, cwd=tmp_path,
                         timeout=600)
    assert res.returncode == 0, res.stdout[-2000:] + res.stderr[-3000:]


@pytest.mark.skipif(importlib.util.find_spec("sphinx") is None or importlib.util.find_spec("myst_parser") is None,
                    reason="the documentation site needs the docs extra: pip install -e '.[docs]'")
def test_the_site_builds_without_warnings_and_every_reference_resolves(tmp_path):
    """sphinx-build -W -n: a docstring or page that points at a name or page that does not exist fails here."""
    res = subprocess.run([sys.executable, "-m", "sphinx", "-W", "-n", "-E", "-q", "-b", "html",
                          "-d", str(tmp_path / "doctrees"), os.path.join(REPO, "docs"), str(tmp_path / "html")],
                         capture_output=True, text=True, cwd=REPO, timeout=900)
    assert res.returncode == 0, res.stdout[-3000:] + res.stderr[-5000:]
    html = tmp_path / "html"
    pages = {p.stem for p in (html / "_api").glob("*.html")}
    # every module of the package has its page, and the re-exported entry point is documented where it is defined
    assert {"openmm_symprk", "openmm_symprk.integrators.symplectic", "openmm_symprk.studies.demo"} <= pages
    assert 'id="openmm_symprk.integrators.symplectic.SymplecticIntegrator"' in \
        (html / "_api" / "openmm_symprk.integrators.symplectic.html").read_text(encoding="utf-8")
    for page in ("index", "theory", "thermostat", "api"):
        assert (html / f"{page}.html").exists(), page


@pytest.mark.skipif(importlib.util.find_spec("sphinx") is None, reason="docs/conf.py needs Sphinx (the docs extra)")
def test_the_site_ignores_only_names_of_other_packages():
    """nitpick_ignore_regex lets references to numpy, OpenMM, ... through unchecked (no intersphinx offline), never
    one to a name of this package."""
    spec = importlib.util.spec_from_file_location("docs_conf", os.path.join(REPO, "docs", "conf.py"))
    conf = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(conf)

    def ignored(target):
        return any(re.fullmatch(t, "py:class") and re.fullmatch(n, target) for t, n in conf.nitpick_ignore_regex)

    assert ignored("numpy.ndarray") and ignored("openmm.System") and ignored("mm.Context") and ignored("float")
    for name in ("openmm_symprk.NoSuchIntegrator", "openmm_symprk.integrators.base.IntegratorBase",
                 "SymplecticIntegrator", ".options.IntegratorOptions", "openmm_symprkx"):
        assert not ignored(name), name
