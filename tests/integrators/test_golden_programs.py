"""The compiled programs (XML, both backends) and native Reference trajectories are those recorded in
tests/integrators/data/golden_programs.json: a refactoring that changes one of them by a single bit fails here.
When a change is intended, regenerate the file with ``python tests/golden.py`` and say why in the commit."""
import json

import pytest

from golden import CONFIGS, DATA, compute
from openmm_symprk import plugin

with open(DATA) as fh:
    GOLDEN = json.load(fh)


@pytest.mark.skipif(not plugin.available(), reason=f"native plugin unavailable: {plugin.unavailable_reason()}")
@pytest.mark.parametrize("name", sorted(CONFIGS))
def test_program_and_trajectory_unchanged(name):
    got = compute([name])
    expected = {k: v for k, v in GOLDEN.items() if k.endswith("/" + name)}
    assert expected, f"no golden entries for {name}"
    assert got == expected
