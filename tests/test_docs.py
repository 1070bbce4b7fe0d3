"""Every Python code block of README.md and docs/*.md runs as written, and every example script runs.

A document's blocks run in order in one namespace, in a scratch folder, like a script that copies them
one after the other; a block preceded by ``<!-- docs-test: skip (reason) -->`` is left out (none is today).
The examples run in a subprocess with ``--quick``.
"""
import glob
import os
import re
import subprocess
import sys
import warnings

import pytest

REPO = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
DOCS = [os.path.join(REPO, "README.md")] + sorted(glob.glob(os.path.join(REPO, "docs", "*.md")))
EXAMPLES = sorted(glob.glob(os.path.join(REPO, "examples", "*.py")))
BLOCK = re.compile(r"(<!-- docs-test: skip[^>]*-->\s*\n)?```python\n(.*?)```", re.S)


def python_blocks(path):
    with open(path, encoding="utf-8") as fh:
        text = fh.read()
    return [(m.group(2), bool(m.group(1))) for m in BLOCK.finditer(text)]


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
