"""The CustomIntegrator program compiles where OpenMM writes its literals as floats (CUDA in single precision writes
``1e30f``; a literal beyond float's range, such as the blow-up guard's former ``1e300``, is a compile error there:
"floating constant is out of range", seen on an H100), and the change of that literal keeps the program's signature,
so a checkpoint saved before it still loads."""
import re

import openmm as mm
import openmm.unit as unit
import pytest

from openmm_symprk import catalogue
from openmm_symprk.integrators import CustomSymplecticIntegrator
from openmm_symprk.integrators.program import NONFINITE_LIMIT2, program_signature

FLOAT_MAX = 3.4028234663852886e38
NUMBER = re.compile(r"(?<![A-Za-z_0-9.])(\d+\.?\d*(?:[eE][-+]?\d+)?)")


def _literals(ig):
    for i in range(ig.getNumComputations()):
        _, _, expr = ig.getComputationStep(i)
        yield from (float(x) for x in NUMBER.findall(expr))


@pytest.mark.parametrize("method", [m.name for m in catalogue.splittings()])
@pytest.mark.parametrize("options", [{}, {"max_speed": 50.0}, {"temperature": 300.0, "random_seed": 1}],
                         ids=["guard", "max_speed", "thermostat"])
def test_every_literal_is_a_float_in_single_precision(method, options, water8):
    ig = CustomSymplecticIntegrator(1 * unit.femtoseconds, method, system=water8.system, **options)
    too_big = sorted({x for x in _literals(ig) if abs(x) >= FLOAT_MAX})
    assert not too_big, f"{method}: literals beyond single precision's range: {too_big}"


def test_the_guard_keeps_the_signature_of_the_program_written_with_1e300(water8):
    ig = CustomSymplecticIntegrator(1 * unit.femtoseconds, "omelyan-2", system=water8.system)
    xml = mm.XmlSerializer.serialize(ig)
    assert f"step({NONFINITE_LIMIT2} - v*v)" in xml
    before = mm.XmlSerializer.deserialize(xml.replace(f"step({NONFINITE_LIMIT2} - v*v)", "step(1e300 - v*v)"))
    assert "step(1e300 - v*v)" in mm.XmlSerializer.serialize(before)
    assert program_signature(before) == program_signature(ig)  # the hash of the program as written before
