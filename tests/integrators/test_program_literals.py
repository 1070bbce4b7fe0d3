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
from openmm_symprk import SymplecticIntegrator
from openmm_symprk.integrators.options import MAX_SPEED_LIMIT
from openmm_symprk.integrators.program import NONFINITE_LIMIT2, program_signature

FLOAT_MAX = 3.4028234663852886e38
NUMBER = re.compile(r"(?<![A-Za-z_0-9.])(\d+\.?\d*(?:[eE][-+]?\d+)?)")


def _literals(ig):
    for i in range(ig.getNumComputations()):
        _, _, expr = ig.getComputationStep(i)
        yield from (float(x) for x in NUMBER.findall(expr))


@pytest.mark.parametrize("method", [m.name for m in catalogue.splittings()])
@pytest.mark.parametrize("options", [{}, {"max_speed": 50.0}, {"max_speed": MAX_SPEED_LIMIT},
                                     {"temperature": 300.0, "random_seed": 1}],
                         ids=["guard", "max_speed", "largest-max_speed", "thermostat"])
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


#: Signatures of the programs as compiled by the code before the guard's literal changed (commit 6523aa3), which the
#: checkpoints saved then hold in global 0.  (The thermostat's middle placement, verlet's default, was 312686532209284
#: then; its step changed on purpose since (it runs from its closing kick), and so did its signature: such a checkpoint
#: is refused by name.  The ends placement's program is the same.)
SIGNATURES_BEFORE = {("omelyan-2", False): 598565899768797, ("verlet", True): 3745317633452134}


@pytest.mark.parametrize("method, thermostat", list(SIGNATURES_BEFORE))
def test_the_signature_is_the_one_checkpoints_saved_before_hold(method, thermostat, water8):
    options = {"temperature": 300.0, "random_seed": 1, "thermostat_position": "ends"} if thermostat else {}
    ig = CustomSymplecticIntegrator(1 * unit.femtoseconds, method, system=water8.system, **options)
    assert ig.program_info.signature == SIGNATURES_BEFORE[method, thermostat]
    assert ig.getGlobalVariableByName("symprk_signature") == SIGNATURES_BEFORE[method, thermostat]


@pytest.mark.parametrize("backend", ["custom", "auto"])
@pytest.mark.parametrize("max_speed", [2e15, 1e20, float("inf"), -1.0])
def test_a_max_speed_whose_square_is_no_float_is_refused_by_name(backend, max_speed, water8):
    """Its square goes into both backends' programs (the native kernel's MAX_SPEED2 too): beyond MAX_SPEED_LIMIT it
    would not compile in single precision on CUDA, so it is refused up front, with the value and the range."""
    expected = r"max_speed must be a speed from 0 to 1e\+15 nm/ps.*got " + re.escape(repr(max_speed))
    with pytest.raises(ValueError, match=expected):
        SymplecticIntegrator(1 * unit.femtoseconds, "verlet", system=water8.system, backend=backend,
                             max_speed=max_speed)
