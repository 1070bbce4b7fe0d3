"""The recommended method and step live in one place, docs/production.md's "What to run" table; README's box "Which
method and step for my system", its first example and examples/production.py quote it, and the example runs (short)
as a production NVT run: no warning, the thermostat's temperature."""
import os
import re
import subprocess
import sys

import pytest

REPO = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
EXAMPLE = os.path.join(REPO, "examples", "production.py")


def _read(*parts):
    with open(os.path.join(REPO, *parts), encoding="utf-8") as fh:
        return fh.read()


def _table(text: str, heading: str) -> list:
    """The rows (lists of cells) of the first Markdown table after ``heading``, less its header."""
    rows = []
    for line in text[text.index(heading):].splitlines():
        if line.startswith("|"):
            cells = [c.strip() for c in line.strip("|").split("|")]
            if not set("".join(cells)) <= set("-: "):  # (not the rule under the header)
                rows.append(cells)
        elif rows:
            break
    return rows[1:]


def _setup(code: str) -> tuple:
    """(step in fs, method) of the SymplecticIntegrator a piece of code builds first."""
    m = re.search(r'SymplecticIntegrator\((\d+(?:\.\d+)?)\*unit\.femtoseconds, "([\w-]+)"', code)
    assert m, code[:500]
    return f"{float(m.group(1)):g} fs", f"`{m.group(2)}`"


@pytest.fixture(scope="module")
def recommendation():
    rows = _table(_read("docs", "production.md"), "## What to run")
    assert len(rows) >= 3 and rows[0][0].startswith("solvated protein")
    return rows


def test_readme_box_quotes_the_table(recommendation):
    box = _table(_read("README.md"), "### Which method and step for my system")
    assert box == [row[:3] for row in recommendation]


def test_readme_first_example_and_the_script_run_the_first_row(recommendation):
    readme = _read("README.md")
    first = re.search(r"```python\n(.*?)```", readme[readme.index("## Use it in your script"):], re.S).group(1)
    system, method, step = recommendation[0][:3]
    for code in (first, _read("examples", "production.py")):
        assert _setup(code) == (step, method)
        for words in ("nonbondedMethod=app.PME", "constraints=app.HBonds", 'ForceField("amber14-all.xml", '
                      '"amber14/tip3p.xml")', "temperature=300*unit.kelvin"):
            assert words in code, words


def test_the_production_example_runs_without_a_warning():
    """The script, short (100 steps of OpenMM's solvated villin), with the package's warnings made errors: a
    production NVT run gets none, and StateDataReporter reads the thermostat's temperature."""
    code = ("import runpy, sys, warnings\n"
            "warnings.simplefilter('error', UserWarning)\n"
            f"sys.argv = [{EXAMPLE!r}, '--quick']\n"
            f"runpy.run_path({EXAMPLE!r}, run_name='__main__')\n")
    res = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, timeout=600,
                         env=dict(os.environ, OPENMM_CPU_THREADS="2"))
    assert res.returncode == 0, res.stdout[-2000:] + res.stderr[-3000:]
    assert "verlet, step 0.002 ps" in res.stdout and "stochastic velocity rescaling at 300 K" in res.stdout
    rows = [line.split(",") for line in res.stdout.splitlines() if re.match(r"\d+,", line)]
    assert [int(r[0]) for r in rows] == [20, 40, 60, 80, 100]
    assert all(250 < float(r[2]) < 350 for r in rows), rows
